# Stage 2: grasp-force optimisation of every (pose, synergy set), sharded over poses so
# that each pose's mechanics (J, G, K, G_K^R, f_p) is built once for all its sets.


rule optimise_shard:
    input:
        contacts=W.step_input("contacts"),
        code=W.code("optimise_shard"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("optimise_shard"),
    log:
        log_file("optimise_shard"),
    benchmark:
        benchmark_file("optimise_shard")
    threads: threads("optimise_shard")
    resources:
        **W.resources("optimise_shard"),
    params:
        cfg=W.step_cfg("optimise"),
    script:
        "../scripts/optimise_shard.py"


rule optimise:
    input:
        shards=W.shard_files("optimise_shard"),
        code=W.code("optimise"),
    output:
        **outputs("optimise"),
    log:
        log_file("optimise"),
    benchmark:
        benchmark_file("optimise")
    threads: threads("optimise")
    resources:
        **W.resources("optimise"),
    script:
        "../scripts/optimise.py"
