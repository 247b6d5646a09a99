"""Snakemake script: the force/torque sensor on the first pin for one planned part
(reads the part's stored plan result; no search of its own)."""
from pipeline.logs import log_to
from pipeline.workflow.sense import sense

with log_to(snakemake.log[0]):  # noqa: F821
    result = sense(snakemake.input.plan, snakemake.config, snakemake.output.sensing)  # noqa: F821
    if result["found"]:
        print(f"mu_c {result['friction']} (profiles at {result['mu_c_profiles']:g}): sensor on "
              f"{result['first_pin']} ({result['y_pin']:g} mm), stored plan #{result['plan_rank']} "
              f"{result['plan']['pins']}: worst {result['worst_sets']} final set(s) per verdict; groups "
              f"{[g['states'] for g in result['groups']]}; {result['note']}")
    else:
        print(result["note"])
