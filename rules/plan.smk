# Stages 3-5: bands of every map, fixed-pins plans, their verification by rollouts.


# One job for the bands of every shard (about 0.1 s each): a job per shard
# spent some 2.5 CPU s on starting Python for each of them (the default
# config's 60 shards: 60 jobs, ~2.7 CPU min, against ~10 s in one).
rule bands:
    input:
        shards=list(JOBS),
    output:
        bands=BAND_FILES,
    params:
        bands=config["bands"],
    log:
        f"{LOGS}/bands.log",
    benchmark:
        f"{LOGS}/benchmark/bands.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/bands.py"


rule plan:
    input:
        # The shards the plan reads and nothing else (pipeline.workflow.plan.planner_shards):
        # the atlas needs only these, and other shards or a re-index re-plan nothing.
        shards=planner_shards,
    output:
        plan=f"{RESULTS}/plans/{{name}}.json",
    params:
        settings={k: config[k] for k in ("planner", "bands", "verify", "speed")},
        sweep={k: config["sweep"][k] for k in ("pin_radius", "kernel")},
    log:
        f"{LOGS}/plan/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/plan/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/plan.py"


rule verify:
    input:
        plan=rules.plan.output.plan,
    output:
        verify=f"{RESULTS}/verify/{{name}}.json",
    params:
        settings=config["verify"],
    log:
        f"{LOGS}/verify/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/verify/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/verify.py"
