# Stage 2: grasp-force optimisation of every (pose, synergy set), sharded over poses so
# that each pose's mechanics (J, G, K, G_K^R, f_p) is built once for all its sets.


rule optimise_shard:
    input:
        contacts=step_input("contacts"),
        code=code("optimise_shard"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        temp("{root}/objects/{object}/gfo_shards/{shard}.parquet"),
    log:
        "{root}/logs/optimise/{object}_{shard}.log",
    benchmark:
        "{root}/benchmarks/optimise/{object}_{shard}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("optimise_shard"),
        runtime=runtime_min("optimise_shard"),
    params:
        cfg=step_cfg("optimise"),
    script:
        "../scripts/optimise_shard.py"


rule aggregate_gfo:
    input:
        shards=lambda w: [
            f"{w.root}/objects/{w.object}/gfo_shards/{i}.parquet"
            for i in range(scenario_config(w)["solver"]["pose_shards"])
        ],
        code=code("aggregate_gfo"),
    output:
        "{root}/objects/{object}/gfo.parquet",
    log:
        "{root}/logs/aggregate_gfo/{object}.log",
    benchmark:
        "{root}/benchmarks/aggregate_gfo/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("aggregate_gfo"),
        runtime=runtime_min("aggregate_gfo"),
    script:
        "../scripts/aggregate_gfo.py"
