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
        # The part's own shards: a re-index ('pinfeed catalog index') or another
        # part's new shards do not re-plan it; the index must exist (ancient).
        shards=part_shards,
        index=ancient(rules.catalog_index.output.index),
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
