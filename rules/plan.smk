# Stages 3-5: bands of every map, fixed-pins plans, their verification by rollouts.


rule bands:
    input:
        shard=f"{CATALOG}/{{family}}/{{part}}/{{model}}/{{tag}}.h5",
    output:
        bands=f"{CATALOG}/bands/{{family}}/{{part}}/{{model}}/{{tag}}.json",
    params:
        bands=config["bands"],
    log:
        "logs/bands/{family}/{part}/{model}/{tag}.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/bands.py"


rule plan:
    input:
        index=rules.catalog_index.output.index,
    output:
        plan=f"{CATALOG}/plans/{{name}}.json",
    params:
        settings={k: config[k] for k in ("planner", "bands", "verify")},
        sweep={k: config["sweep"][k] for k in ("pin_radius", "kernel")},
    log:
        "logs/plan/{name}.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/plan.py"


rule verify:
    input:
        plan=rules.plan.output.plan,
    output:
        verify=f"{CATALOG}/verify/{{name}}.json",
    params:
        settings=config["verify"],
    log:
        "logs/verify/{name}.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/verify.py"
