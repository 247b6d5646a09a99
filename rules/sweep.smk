# Stage 1: one map shard per (family, part, model, mu_c, v_pin[, belt speed][, support]).


rule sweep_shard:
    output:
        shard=f"{CATALOG}/{{family}}/{{part}}/{{model}}/{{tag}}.h5",
    params:
        spec=shard_params,
    log:
        "logs/sweep/{family}/{part}/{model}/{tag}.log",
    benchmark:
        "logs/benchmark/sweep/{family}/{part}/{model}/{tag}.tsv"
    threads: shard_threads()
    resources:
        mem_mb=1000,
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/sweep_shard.py"
