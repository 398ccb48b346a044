# Stage 1: close the hand on each object at every pose (pybullet), and the pictures of
# the hand (Fig. 1) and of example grasps (Fig. 2).


rule search_placement:
    input:
        code=code("search_placement"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        "{root}/objects/{object}/placement.csv",
    log:
        "{root}/logs/search_placement/{object}.log",
    benchmark:
        "{root}/benchmarks/search_placement/{object}.tsv"
    threads: 2
    resources:
        mem_mb=mem_mb("search_placement"),
        runtime=runtime_min("search_placement"),
    params:
        cfg=step_cfg("search"),
    script:
        "../scripts/search_placement.py"


rule simulate_contacts:
    input:
        code=code("simulate_contacts"),
        data=SHIPPED_DATA,
        user=user_files,
        search=searched_input,
    output:
        "{root}/objects/{object}/contacts.parquet",
    log:
        "{root}/logs/simulate_contacts/{object}.log",
    benchmark:
        "{root}/benchmarks/simulate_contacts/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("simulate_contacts"),
        runtime=runtime_min("simulate_contacts"),
    params:
        cfg=step_cfg("simulate"),
    script:
        "../scripts/simulate_contacts.py"


rule select_contacts:
    input:
        contacts=step_input("simulate"),
        code=code("select_contacts"),
    output:
        "{root}/objects/{object}/load_carrying_contacts.parquet",
    log:
        "{root}/logs/select_contacts/{object}.log",
    benchmark:
        "{root}/benchmarks/select_contacts/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("select_contacts"),
        runtime=runtime_min("select_contacts"),
    params:
        cfg=step_cfg("contacts"),
    script:
        "../scripts/select_contacts.py"


rule fig1_synergy_postures:
    input:
        code=code("fig1_synergy_postures"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        png=report(
            "{root}/figures/fig1_synergy_postures.png",
            caption="../report/fig1.rst",
            category="Figures",
        ),
        pdf="{root}/figures/fig1_synergy_postures.pdf",
    log:
        "{root}/logs/fig1_synergy_postures.log",
    benchmark:
        "{root}/benchmarks/fig1_synergy_postures.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("fig1_synergy_postures"),
        runtime=runtime_min("fig1_synergy_postures"),
    params:
        cfg=step_cfg("fig1"),
    script:
        "../scripts/fig1_synergy_postures.py"


rule fig2_example_grasps:
    input:
        contacts=step_inputs("contacts"),
        code=code("fig2_example_grasps"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        png=report(
            "{root}/figures/fig2_example_grasps.png",
            caption="../report/fig2.rst",
            category="Figures",
        ),
        pdf="{root}/figures/fig2_example_grasps.pdf",
    log:
        "{root}/logs/fig2_example_grasps.log",
    benchmark:
        "{root}/benchmarks/fig2_example_grasps.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("fig2_example_grasps"),
        runtime=runtime_min("fig2_example_grasps"),
    params:
        cfg=step_cfg("fig2"),
    script:
        "../scripts/fig2_example_grasps.py"
