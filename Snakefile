# pinfeed workflow: sweep part families x models x friction into map shards,
# index them into the catalog, then bands, plans, verification, figures, report.
#
#   snakemake --cores all                       # default config (the paper's set-up)
#   snakemake --cores all support_study         # + the support-family study (long; not in 'all')
#   snakemake --cores all design                # + design for feeding (not in 'all')
#   snakemake --cores 16 --configfile config/workstation.yaml
import os
import sys

from snakemake.utils import min_version

from pipeline.config import config_name, validate_config
from pipeline.workflow.runner import reconcile_catalog

min_version("8.0")


# The embedded default, unless --configfile gave a whole config (Snakemake
# would otherwise merge the two family lists).
if not {"families", "sweep"} & set(config):

    configfile: os.path.join(workflow.basedir, "config", "config.yaml")



# Schema validation (descriptions in config/schema.yaml), defaults filled in,
# part outlines checked: a bad config stops here, before any job runs.
# Relative outline paths are relative to the last --configfile's folder; its
# stem names the config (results go to results_dir/NAME/) unless it says name:.
_CONFIG_FILES = list(getattr(workflow, "configfiles", None) or [])
config.update(validate_config(
    config, base_dir=os.path.dirname(os.path.abspath(_CONFIG_FILES[-1])) if _CONFIG_FILES else None,
    name=config_name(_CONFIG_FILES[-1]) if _CONFIG_FILES else None))


report: "rules/report/workflow.rst"


# The catalog against disk, before Snakemake plans its jobs: a deleted or
# damaged shard removes the stale index, so this run recomputes it
# (pipeline/workflow/runner.py says why Snakemake would not).
if workflow.is_main_process:
    for note in reconcile_catalog(config):
        print(f"pinfeed: {note}", file=sys.stderr)


include: "rules/common.smk"
include: "rules/sweep.smk"
include: "rules/catalog.smk"
include: "rules/plan.smk"
include: "rules/sense.smk"
include: "rules/layout.smk"
include: "rules/speed.smk"
include: "rules/atlas.smk"
include: "rules/report.smk"
# the support study: its own target (rule support_study), after the report it extends
include: "rules/support.smk"
# design for feeding: its own target (rule design), for the parts pins do not orient
include: "rules/design.smk"
# a parts library (config key library): its own target (rule library), and in 'all' when configured
include: "rules/library.smk"


rule all:
    input:
        rules.catalog_index.output.index,
        BAND_FILES,
        rules.atlas.output.json,
        rules.report.output.report,
        LIBRARY_TARGETS,
    default_target: True
