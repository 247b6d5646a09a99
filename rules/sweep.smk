# Stage 1: one map shard per (family, part, model, mu_c).


rule sweep_shard:
    output:
        shard=f"{CATALOG}/{{family}}/{{part}}/{{model}}/mu_c={{mu}}.h5",
    params:
        spec=shard_params,
    log:
        "logs/sweep/{family}/{part}/{model}/mu_c={mu}.log",
    threads: 2
    resources:
        mem_mb=1000,
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/sweep_shard.py"
