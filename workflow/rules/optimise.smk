# Stage 2: grasp-force optimisation of every (pose, synergy set), sharded over poses so
# that each pose's mechanics (J, G, K, G_K^R, f_p) is built once for all its sets.


rule optimise_shard:
    input:
        contacts="results/objects/{object}/contacts.parquet",
        code=code("optimise_shard"),
        data=SHIPPED_DATA,
        user=user_files(),
    output:
        temp("results/objects/{object}/gfo_shards/{shard}.parquet"),
    log:
        "results/logs/optimise/{object}_{shard}.log",
    benchmark:
        "results/benchmarks/optimise/{object}_{shard}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("optimise_shard"),
        runtime=runtime_min("optimise_shard"),
    params:
        opt=optimisation_params,
        n_shards=len(SHARDS),
    script:
        "../scripts/optimise_shard.py"


rule aggregate_gfo:
    input:
        shards=expand("results/objects/{{object}}/gfo_shards/{shard}.parquet", shard=SHARDS),
        code=code("aggregate_gfo"),
    output:
        "results/objects/{object}/gfo.parquet",
    log:
        "results/logs/aggregate_gfo/{object}.log",
    benchmark:
        "results/benchmarks/aggregate_gfo/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("aggregate_gfo"),
        runtime=runtime_min("aggregate_gfo"),
    script:
        "../scripts/aggregate_gfo.py"
