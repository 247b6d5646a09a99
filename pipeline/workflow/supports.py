"""The function of ``rules/support.smk``: a part's plans against a support family."""
from __future__ import annotations

from pipeline.config import config_hash
from pipeline.maps.io import write_json
from pipeline.parts.part import Part
from pipeline.planning import PlannerSettings, support_study, validate_plan_file
from pipeline.present.figures import placeholder
from pipeline.present.figures.supports import plot_support_maps
from pipeline.provenance import provenance_attrs


def studied_parts(config: dict) -> list[str]:
    """Parts the support study covers: ``support_study.parts`` (default every
    planned part); none when ``support_study.family`` is not set."""
    study = config.get("support_study") or {}
    if not study.get("family"):
        return []
    return list(study.get("parts") or config["planner"]["parts"])


def support_part(plan_path, config: dict, out, figure, progress=print) -> dict:
    """Rule ``support``: :func:`~pipeline.planning.plans.support_study.support_study`
    of the part of the stored plans at ``plan_path`` (its recommended tight
    plan at ``planner.mu_c``) against ``support_study.family``; the JSON to
    ``out`` (with provenance) and the overlaid maps (swept friction nearest
    the planner's nominal one, the ``figures.d`` panels) to ``figure``."""
    stored = validate_plan_file(plan_path)
    part = Part.from_dict(stored["part"])
    uniform = (stored.get("tight") or [None])[0]
    family = config["support_study"]["family"]
    settings = PlannerSettings.from_config(config)
    result = support_study(part, settings, family, uniform, progress=progress)
    spreads = result.pop("_spreads")
    mu = settings.friction.nominal
    near = min(spreads, key=lambda m: abs(m - mu))
    write_json({**result, "figure_mu_c": near, "config_hash": config_hash(config), **provenance_attrs()}, out)
    spread = spreads[near]
    if spread.maps.sizes["support"]:
        plot_support_maps(spread, config["figures"]["d"],
                          f"{part.name}: configuration maps under uniform support and the family "
                          f"{family} ({len(result['family']['members'])} members), minpower, "
                          f"$\\mu_c$ = {near:g}", figure)
    else:  # pragma: no cover - a family has members
        placeholder(figure, f"{part.name}: no support family")
    return result


def support_summary_text(result: dict) -> str:
    """The three numbers in one sentence (for logs and the report)."""
    s = result["spread"]
    text = (f"{result['part']}: theta_f moves by median {s['shift_median_deg']} deg, p90 "
            f"{s['shift_p90_deg']} deg, max {s['shift_max_deg']} deg between uniform and "
            f"{s['family']} over {s['cells_compared']} map cells")
    if result["survives"] is None:
        return text + "; no recommended plan to replay"
    if result["survives"]:
        return text + "; the recommended plan survives the family"
    fam = result["family_plan"] or {}
    rec = " ".join(result["uniform_plan"] or [])
    widen = result.get("widening") or {}
    if widen.get("family_width_deg") is not None:
        rec += (f" (its final set widens from {widen['uniform_width_deg']:.1f} to "
                f"{widen['family_width_deg']:.1f} deg)")
    return (text + f"; the recommended plan {rec} does not survive it"
            + (f"; {' '.join(fam['pins'])} orients the part for every member" if fam.get("orients")
               else f"; {fam.get('evidence', 'no plan found')}" + _worst_text(fam.get("worst_member"))))


def _worst_text(worst: dict | None) -> str:
    """The member that broke the best plan, in a clause (empty without one)."""
    if not worst:
        return ""
    return (f"; the family's worst member found (legs {worst['parameters'].get('legs_mm', worst['parameters'])}) "
            f"ends {worst['outside_deg']:.1f} deg outside the set of {' '.join(worst['plan'])}")
