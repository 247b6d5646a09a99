# Stages 3-5: bands of every map, fixed-pins plans, their verification by rollouts.


rule bands:
    input:
        shard=f"{CATALOG}/{{family}}/{{part}}/{{model}}/{{tag}}.h5",
    output:
        bands=f"{RESULTS}/bands/{{family}}/{{part}}/{{model}}/{{tag}}.json",
    params:
        bands=config["bands"],
    log:
        f"{LOGS}/bands/{{family}}/{{part}}/{{model}}/{{tag}}.log",
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
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/verify.py"
