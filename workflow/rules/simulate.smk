# Stage 1: close the hand on each object at every pose (pybullet), and the pictures of
# the hand (Fig. 1) and of example grasps (Fig. 2).


rule simulate_contacts:
    input:
        code=code("simulate_contacts"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        "{root}/objects/{object}/contacts.parquet",
    params:
        cfg=step_cfg("simulate"),
    log:
        "{root}/logs/simulate_contacts/{object}.log",
    benchmark:
        "{root}/benchmarks/simulate_contacts/{object}.tsv"
    script:
        "../scripts/simulate_contacts.py"


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
    params:
        cfg=step_cfg("fig1"),
    log:
        "{root}/logs/fig1_synergy_postures.log",
    script:
        "../scripts/fig1_synergy_postures.py"


rule fig2_example_grasps:
    input:
        contacts=step_inputs("simulate"),
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
    params:
        cfg=step_cfg("fig2"),
    log:
        "{root}/logs/fig2_example_grasps.log",
    script:
        "../scripts/fig2_example_grasps.py"
