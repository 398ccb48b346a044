# Stage 4: the study's figures: the hand along the synergies (Fig. 1), example grasps
# (Fig. 2, and in 3-D in the browser), the workflow's own rule graph (Fig. 3), force maps per
# object (Fig. 4) and the hierarchy (Fig. 5).


rule fig4_force_maps:
    input:
        gfo=step_input("optimise"),
        minima=step_input("minima"),
        code=code("fig4_force_maps"),
    output:
        maps_png=report(
            "{root}/objects/{object}/fig4_force_maps.png",
            caption="../report/fig4_force_maps.rst",
            category="Fig. 4",
            subcategory="{object}",
        ),
        maps_pdf="{root}/objects/{object}/fig4_force_maps.pdf",
        exploded_png=report(
            "{root}/objects/{object}/fig4_exploded.png",
            caption="../report/fig4_exploded.rst",
            category="Fig. 4",
            subcategory="{object}",
        ),
        exploded_pdf="{root}/objects/{object}/fig4_exploded.pdf",
    log:
        "{root}/logs/fig4/{object}.log",
    benchmark:
        "{root}/benchmarks/fig4/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("fig4_force_maps"),
        runtime=runtime_min("fig4_force_maps"),
    params:
        cfg=step_cfg("fig4"),
    script:
        "../scripts/fig4_force_maps.py"


rule fig5_hierarchy:
    input:
        hierarchy=study_input("tables", "tables/hierarchy.csv"),
        code=code("fig5_hierarchy"),
    output:
        success_png=report(
            "{root}/figures/fig5a_hierarchy_success.png",
            caption="../report/fig5a.rst",
            category="Figures",
        ),
        success_pdf="{root}/figures/fig5a_hierarchy_success.pdf",
        pooled_png=report(
            "{root}/figures/fig5a_hierarchy_success_pooled.png",
            caption="../report/fig5a_pooled.rst",
            category="Figures",
        ),
        pooled_pdf="{root}/figures/fig5a_hierarchy_success_pooled.pdf",
        force_png=report(
            "{root}/figures/fig5b_hierarchy_force.png",
            caption="../report/fig5b.rst",
            category="Figures",
        ),
        force_pdf="{root}/figures/fig5b_hierarchy_force.pdf",
    log:
        "{root}/logs/fig5_hierarchy.log",
    benchmark:
        "{root}/benchmarks/fig5_hierarchy.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("fig5_hierarchy"),
        runtime=runtime_min("fig5_hierarchy"),
    params:
        cfg=step_cfg("fig5"),
    script:
        "../scripts/fig5_hierarchy.py"


rule fig3_rulegraph:
    input:
        rules=[str(p) for p in sorted((ROOT / "workflow" / "rules").glob("*.smk"))],
        snakefile=str(ROOT / "Snakefile"),
        code=code("fig3_rulegraph"),
    output:
        png=report(
            "results/figures/fig3_rulegraph.png",
            caption="../report/fig3.rst",
            category="Figures",
        ),
        pdf="results/figures/fig3_rulegraph.pdf",
        dot="results/figures/fig3_rulegraph.dot",
    log:
        "results/logs/fig3_rulegraph.log",
    benchmark:
        "results/benchmarks/fig3_rulegraph.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("fig3_rulegraph"),
        runtime=runtime_min("fig3_rulegraph"),
    params:
        # the rule graph does not depend on the configuration's values: drawn with the
        # shipped one, so that neither a config value nor a config file's path reruns it
        configfile=str(ROOT / "config" / "config.yaml"),
    script:
        "../scripts/fig3_rulegraph.py"


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
        pages=pages_in_report(
            "{root}/figures/grasps_3d",
            caption="../report/grasps_3d.rst",
            category="Figures",
        ),
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


rule placement_map:
    input:
        placement=step_input("search"),
        contacts=step_input("contacts"),
        code=code("placement_map"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        png=report(
            "{root}/objects/{object}/placement_map.png",
            caption="../report/placement_map.rst",
            category="Placement search",
            subcategory="{object}",
        ),
        pdf="{root}/objects/{object}/placement_map.pdf",
    log:
        "{root}/logs/placement_map/{object}.log",
    benchmark:
        "{root}/benchmarks/placement_map/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("placement_map"),
        runtime=runtime_min("placement_map"),
    params:
        cfg=step_cfg("search"),
    script:
        "../scripts/placement_map.py"
