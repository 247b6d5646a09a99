# Stage 2: the catalog index, rebuilt from the shards on disk.


rule catalog_index:
    input:
        shards=list(JOBS),
    output:
        index=f"{CATALOG}/index.json",
    log:
        "logs/catalog/index.log",
    benchmark:
        "logs/benchmark/catalog/index.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/catalog_index.py"
