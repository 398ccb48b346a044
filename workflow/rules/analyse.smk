# Stage 3: local minima per object and set, success rates, and the study's tables.


rule local_minima:
    input:
        gfo="results/objects/{object}/gfo.parquet",
        code=code("local_minima"),
    output:
        "results/objects/{object}/minima.parquet",
    params:
        cfg=step_cfg("minima"),
    log:
        "results/logs/local_minima/{object}.log",
    script:
        "../scripts/local_minima.py"


rule study_tables:
    input:
        gfo=expand("results/objects/{object}/gfo.parquet", object=OBJECTS),
        minima=expand("results/objects/{object}/minima.parquet", object=OBJECTS),
        code=code("study_tables"),
    output:
        **{
            f"{t}_{ext}": report(
                f"results/tables/{t}.{ext}", caption=f"../report/{t}.rst", category="Tables"
            )
            if ext == "csv"
            else f"results/tables/{t}.{ext}"
            for t in TABLES
            for ext in ("csv", "md")
        },
    params:
        cfg=step_cfg("tables"),
    log:
        "results/logs/study_tables.log",
    script:
        "../scripts/study_tables.py"


rule grasp_realism:
    input:
        contacts=expand("results/objects/{object}/contacts.parquet", object=OBJECTS),
        gfo=expand("results/objects/{object}/gfo.parquet", object=OBJECTS),
        code=code("grasp_realism"),
        data=SHIPPED_DATA,
        user=user_files(),
    output:
        csv=report(
            "results/tables/grasp_realism.csv",
            caption="../report/grasp_realism_table.rst",
            category="Tables",
        ),
        md="results/tables/grasp_realism.md",
        png=report(
            "results/figures/grasp_realism.png",
            caption="../report/grasp_realism.rst",
            category="Figures",
        ),
        pdf="results/figures/grasp_realism.pdf",
    params:
        cfg=step_cfg("realism"),
    log:
        "results/logs/grasp_realism.log",
    script:
        "../scripts/grasp_realism.py"
