# Stage 3: local minima per object and set, success rates, and the study's tables.


rule local_minima:
    input:
        gfo=step_input("optimise"),
        code=code("local_minima"),
    output:
        "{root}/objects/{object}/minima.parquet",
    log:
        "{root}/logs/local_minima/{object}.log",
    benchmark:
        "{root}/benchmarks/local_minima/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("local_minima"),
        runtime=runtime_min("local_minima"),
    params:
        cfg=step_cfg("minima"),
    script:
        "../scripts/local_minima.py"


rule study_tables:
    input:
        gfo=step_inputs("optimise"),
        minima=step_inputs("minima"),
        code=code("study_tables"),
    output:
        **{
            f"{t}_{ext}": (
                report(
                    f"{{root}}/tables/{t}.{ext}",
                    caption=f"../report/{t}.rst",
                    category="Tables",
                )
                if ext == "csv"
                else f"{{root}}/tables/{t}.{ext}"
            )
            for t in TABLES
            for ext in ("csv", "md")
        },
    log:
        "{root}/logs/study_tables.log",
    benchmark:
        "{root}/benchmarks/study_tables.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("study_tables"),
        runtime=runtime_min("study_tables"),
    params:
        cfg=step_cfg("tables"),
    script:
        "../scripts/study_tables.py"


rule grasp_realism:
    input:
        contacts=step_inputs("contacts"),
        gfo=step_inputs("optimise"),
        code=code("grasp_realism"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        csv=report(
            "{root}/tables/grasp_realism.csv",
            caption="../report/grasp_realism_table.rst",
            category="Tables",
        ),
        md="{root}/tables/grasp_realism.md",
        links_csv="{root}/tables/grasp_links.csv",
        links_md="{root}/tables/grasp_links.md",
        png=report(
            "{root}/figures/grasp_realism.png",
            caption="../report/grasp_realism.rst",
            category="Figures",
        ),
        pdf="{root}/figures/grasp_realism.pdf",
        graspable_csv=report(
            "{root}/tables/graspable_objects.csv",
            caption="../report/graspable_objects.rst",
            category="Tables",
        ),
        graspable_md="{root}/tables/graspable_objects.md",
    log:
        "{root}/logs/grasp_realism.log",
    benchmark:
        "{root}/benchmarks/grasp_realism.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("grasp_realism"),
        runtime=runtime_min("grasp_realism"),
    params:
        cfg=step_cfg("realism"),
    script:
        "../scripts/grasp_realism.py"


rule grasp_quality:
    input:
        contacts=step_input("contacts"),
        gfo=step_input("optimise"),
        code=code("grasp_quality"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        table="{root}/objects/{object}/quality.parquet",
        png=report(
            "{root}/objects/{object}/quality_maps.png",
            caption="../report/quality_maps.rst",
            category="Quality",
            subcategory="{object}",
        ),
        pdf="{root}/objects/{object}/quality_maps.pdf",
    log:
        "{root}/logs/grasp_quality/{object}.log",
    benchmark:
        "{root}/benchmarks/grasp_quality/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("grasp_quality"),
        runtime=runtime_min("grasp_quality"),
    params:
        cfg=step_cfg("quality"),
    script:
        "../scripts/grasp_quality.py"


# The study's claims at every target of the placement search (docs/placement_search.md):
# made by `snakemake -j2 placement_claims` only (~1 s of CPU per target), not by `figures`.
rule target_claims:
    input:
        placement=step_input("search"),
        code=code("target_claims"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        "{root}/objects/{object}/target_claims.parquet",
    log:
        "{root}/logs/target_claims/{object}.log",
    benchmark:
        "{root}/benchmarks/target_claims/{object}.tsv"
    threads: 2
    resources:
        mem_mb=mem_mb("target_claims"),
        runtime=runtime_min("target_claims"),
    params:
        cfg=step_cfg("target_claims"),
    script:
        "../scripts/target_claims.py"


rule summarise_target_claims:
    input:
        claims=searched_inputs("target_claims"),
        code=code("summarise_target_claims"),
    output:
        csv=report(
            "{root}/tables/placement_claims.csv",
            caption="../report/placement_claims.rst",
            category="Placement search",
        ),
        md="{root}/tables/placement_claims.md",
        png=report(
            "{root}/figures/placement_claims.png",
            caption="../report/placement_claims.rst",
            category="Placement search",
        ),
        pdf="{root}/figures/placement_claims.pdf",
    log:
        "{root}/logs/summarise_target_claims.log",
    benchmark:
        "{root}/benchmarks/summarise_target_claims.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("summarise_target_claims"),
        runtime=runtime_min("summarise_target_claims"),
    script:
        "../scripts/summarise_target_claims.py"


# The incremental planner against the exhaustive search (docs/planner.md): made by
# `snakemake -j2 plan` (or `synergrasp plan OBJECT`), not by `figures`.
rule incremental_plan:
    input:
        contacts=step_input("contacts"),
        gfo=step_input("optimise"),
        code=code("incremental_plan"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        plan="{root}/objects/{object}/plan.csv",
        enrollment="{root}/objects/{object}/enrollment.csv",
        png="{root}/objects/{object}/plan.png",
        pdf="{root}/objects/{object}/plan.pdf",
    log:
        "{root}/logs/incremental_plan/{object}.log",
    benchmark:
        "{root}/benchmarks/incremental_plan/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("incremental_plan"),
        runtime=runtime_min("incremental_plan"),
    params:
        cfg=step_cfg("plan"),
    script:
        "../scripts/incremental_plan.py"


rule objects_summary:
    input:
        success_rates=study_input("tables", "tables/success_rates.csv"),
        preservation=study_input("tables", "tables/minimum_preservation.csv"),
        graspable=study_input("realism", "tables/graspable_objects.csv"),
        plans=plan_inputs("plan.csv"),
        enrollment=plan_inputs("enrollment.csv"),
        manifest=random_objects_manifest,
        code=code("objects_summary"),
    output:
        csv="{root}/tables/objects_summary.csv",
        md="{root}/tables/objects_summary.md",
        intervals_csv="{root}/tables/objects_intervals.csv",
        intervals_md="{root}/tables/objects_intervals.md",
        drawn_csv="{root}/tables/random_objects.csv",
        drawn_md="{root}/tables/random_objects.md",
        png="{root}/figures/objects_summary.png",
        pdf="{root}/figures/objects_summary.pdf",
    log:
        "{root}/logs/objects_summary.log",
    benchmark:
        "{root}/benchmarks/objects_summary.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("objects_summary"),
        runtime=runtime_min("objects_summary"),
    params:
        cfg=step_cfg("objects_summary"),
    script:
        "../scripts/objects_summary.py"
