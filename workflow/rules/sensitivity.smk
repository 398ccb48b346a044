# The sensitivity sweep's summary across every scenario (docs/sensitivity.md).


rule sensitivity_summary:
    input:
        claims=scenario_tables("claims"),
        table2=scenario_tables("table2_success_rates"),
        success_rates=scenario_tables("success_rates"),
        preservation=scenario_tables("minimum_preservation"),
        realism=scenario_tables("grasp_realism", step="realism"),
        code=code("sensitivity_summary"),
    output:
        csv=report(
            "results/sensitivity/claims.csv",
            caption="../report/sensitivity_claims.rst",
            category="Sensitivity",
        ),
        md="results/sensitivity/claims.md",
        grid_png=report(
            "results/sensitivity/claims_grid.png",
            caption="../report/sensitivity_grid.rst",
            category="Sensitivity",
        ),
        grid_pdf="results/sensitivity/claims_grid.pdf",
        curves_png=report(
            "results/sensitivity/table2_curves.png",
            caption="../report/sensitivity_table2.rst",
            category="Sensitivity",
        ),
        curves_pdf="results/sensitivity/table2_curves.pdf",
    log:
        "results/logs/sensitivity_summary.log",
    benchmark:
        "results/benchmarks/sensitivity_summary.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("sensitivity_summary"),
        runtime=runtime_min("sensitivity_summary"),
    params:
        scenarios=list(SCENARIOS),
        placements=lambda wildcards: [placement_label(s) for s in SCENARIOS],
    script:
        "../scripts/sensitivity_summary.py"
