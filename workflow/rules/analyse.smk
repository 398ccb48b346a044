# Stage 3: local minima per object and set, success rates, and the study's tables.


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
        radius_deg=config["analyses"]["minima_radius_deg"],
    script:
        "../scripts/study_tables.py"
