# Stage 3: local minima per object and set, success rates, and the study's tables.
from synergrasp.analysis.verdicts import success_verdict


rule local_minima:
    input:
        gfo="results/objects/{object}/gfo.parquet",
        code=code("local_minima"),
    output:
        "results/objects/{object}/minima.parquet",
    log:
        "results/logs/local_minima/{object}.log",
    benchmark:
        "results/benchmarks/local_minima/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("local_minima"),
        runtime=runtime_min("local_minima"),
    params:
        radius_deg=config["analyses"]["minima_radius_deg"],
        success=success_verdict(config["analyses"]),
    script:
        "../scripts/local_minima.py"


rule study_tables:
    input:
        gfo=expand("results/objects/{object}/gfo.parquet", object=OBJECTS),
        minima=expand("results/objects/{object}/minima.parquet", object=OBJECTS),
        code=code("study_tables"),
    output:
        **{
            f"{t}_{ext}": (
                report(
                    f"results/tables/{t}.{ext}",
                    caption=f"../report/{t}.rst",
                    category="Tables",
                )
                if ext == "csv"
                else f"results/tables/{t}.{ext}"
            )
            for t in TABLES
            for ext in ("csv", "md")
        },
    log:
        "results/logs/study_tables.log",
    benchmark:
        "results/benchmarks/study_tables.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("study_tables"),
        runtime=runtime_min("study_tables"),
    params:
        sets=config["synergy_sets"],
        table2_k_max=config["analyses"]["table2_k_max"],
        analyses={k: v for k, v in config["analyses"].items() if k != "fig4"},
        objects={name: object_config(name) for name in OBJECTS},
        grid=config["grid"],
        hand=config["hand"],
        g_m_per_s2=config["mechanics"]["g_m_per_s2"],
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
    log:
        "results/logs/grasp_realism.log",
    benchmark:
        "results/benchmarks/grasp_realism.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("grasp_realism"),
        runtime=runtime_min("grasp_realism"),
    params:
        hand=config["hand"],
        full_set_id=incremental_set_id(config["synergy_sets"]["incremental_max"]),
        weights_N={
            name: spec["mass_kg"] * config["mechanics"]["g_m_per_s2"]
            for name, spec in config["objects"].items()
        },
    script:
        "../scripts/grasp_realism.py"
