# Stage 4: the study's figures: the hand along the synergies (Fig. 1), example grasps
# (Fig. 2, and in 3-D in the browser), the workflow's own rule graph (Fig. 3), force maps per
# object (Fig. 4), the hierarchy (Fig. 5) and the placement search's map.


rule fig4:
    input:
        gfo=W.step_input("optimise"),
        minima=W.step_input("minima"),
        code=W.code("fig4"),
    output:
        **outputs("fig4"),
    log:
        log_file("fig4"),
    benchmark:
        benchmark_file("fig4")
    threads: threads("fig4")
    resources:
        **W.resources("fig4"),
    params:
        cfg=W.step_cfg("fig4"),
    script:
        "../scripts/fig4.py"


rule fig5:
    input:
        hierarchy=W.study_input("tables", "tables/hierarchy.csv"),
        code=W.code("fig5"),
    output:
        **outputs("fig5"),
    log:
        log_file("fig5"),
    benchmark:
        benchmark_file("fig5")
    threads: threads("fig5")
    resources:
        **W.resources("fig5"),
    params:
        cfg=W.step_cfg("fig5"),
    script:
        "../scripts/fig5.py"


rule fig3:
    input:
        rules=[str(p) for p in sorted((ROOT / "workflow" / "rules").glob("*.smk"))],
        snakefile=str(ROOT / "Snakefile"),
        code=W.code("fig3"),
    output:
        **outputs("fig3"),
    log:
        log_file("fig3"),
    benchmark:
        benchmark_file("fig3")
    threads: threads("fig3")
    resources:
        **W.resources("fig3"),
    params:
        # the rule graph does not depend on the configuration's values: drawn with the
        # shipped one, so that neither a config value nor a config file's path reruns it
        configfile=str(ROOT / "config" / "config.yaml"),
    script:
        "../scripts/fig3.py"


rule fig1:
    input:
        code=W.code("fig1"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("fig1"),
    log:
        log_file("fig1"),
    benchmark:
        benchmark_file("fig1")
    threads: threads("fig1")
    resources:
        **W.resources("fig1"),
    params:
        cfg=W.step_cfg("fig1"),
    script:
        "../scripts/fig1.py"


rule hand_reach:
    input:
        code=W.code("hand_reach"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("hand_reach"),
    log:
        log_file("hand_reach"),
    benchmark:
        benchmark_file("hand_reach")
    threads: threads("hand_reach")
    resources:
        **W.resources("hand_reach"),
    params:
        cfg=W.step_cfg("hand_reach"),
    script:
        "../scripts/hand_reach.py"


rule fig2:
    input:
        contacts=W.step_inputs("contacts"),
        code=W.code("fig2"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("fig2"),
    log:
        log_file("fig2"),
    benchmark:
        benchmark_file("fig2")
    threads: threads("fig2")
    resources:
        **W.resources("fig2"),
    params:
        cfg=W.step_cfg("fig2"),
    script:
        "../scripts/fig2.py"


rule placement_map:
    input:
        placement=W.step_input("search"),
        contacts=W.step_input("contacts"),
        code=W.code("placement_map"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("placement_map"),
    log:
        log_file("placement_map"),
    benchmark:
        benchmark_file("placement_map")
    threads: threads("placement_map")
    resources:
        **W.resources("placement_map"),
    params:
        cfg=W.step_cfg("search"),
    script:
        "../scripts/placement_map.py"
