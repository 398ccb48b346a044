# The sensitivity sweep's summary across every scenario (docs/sensitivity.md); its rule is
# the target `sensitivity`: it pulls each scenario's tables and grasp-realism table and what
# they need, not each scenario's figures (`scenarios` makes those).


rule sensitivity:
    input:
        claims=W.scenario_tables("claims"),
        table2=W.scenario_tables("table2_success_rates"),
        success_rates=W.scenario_tables("success_rates"),
        preservation=W.scenario_tables("minimum_preservation"),
        realism=W.scenario_tables("grasp_realism", step="realism"),
        code=W.code("sensitivity"),
    output:
        **outputs("sensitivity"),
    log:
        log_file("sensitivity"),
    benchmark:
        benchmark_file("sensitivity")
    threads: threads("sensitivity")
    resources:
        **W.resources("sensitivity"),
    params:
        scenarios=list(SCENARIOS),
        placements=lambda wildcards: [W.placement_label(s) for s in SCENARIOS],
    script:
        "../scripts/sensitivity.py"
