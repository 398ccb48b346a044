# Stage 3: local minima per object and set, grasp quality, the study's tables, grasp
# realism, and the claims at every target of the placement search.


rule minima:
    input:
        gfo=W.step_input("optimise"),
        code=W.code("minima"),
    output:
        **outputs("minima"),
    log:
        log_file("minima"),
    benchmark:
        benchmark_file("minima")
    threads: threads("minima")
    resources:
        **W.resources("minima"),
    params:
        cfg=W.step_cfg("minima"),
    script:
        "../scripts/minima.py"


# Planners compared at equal cost, replayed on every object's gfo table (docs/planner.md).
rule planners:
    input:
        contacts=W.step_inputs("contacts"),
        gfo=W.step_inputs("optimise"),
        code=W.code("planners"),
    output:
        **outputs("planners"),
    log:
        log_file("planners"),
    benchmark:
        benchmark_file("planners")
    threads: threads("planners")
    resources:
        **W.resources("planners"),
    params:
        cfg=W.step_cfg("planners"),
    script:
        "../scripts/planners.py"


rule tables:
    input:
        gfo=W.step_inputs("optimise"),
        minima=W.step_inputs("minima"),
        planners=W.study_input("planners", "tables/planners.csv"),
        code=W.code("tables"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("tables"),
    log:
        log_file("tables"),
    benchmark:
        benchmark_file("tables")
    threads: threads("tables")
    resources:
        **W.resources("tables"),
    params:
        cfg=W.step_cfg("tables"),
    script:
        "../scripts/tables.py"


rule realism:
    input:
        contacts=W.step_inputs("contacts"),
        gfo=W.step_inputs("optimise"),
        placements=W.step_inputs("search"),
        manifest=W.random_objects_manifest,
        code=W.code("realism"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("realism"),
    log:
        log_file("realism"),
    benchmark:
        benchmark_file("realism")
    threads: threads("realism")
    resources:
        **W.resources("realism"),
    params:
        cfg=W.step_cfg("realism"),
    script:
        "../scripts/realism.py"


rule quality:
    input:
        contacts=W.step_input("contacts"),
        gfo=W.step_input("optimise"),
        code=W.code("quality"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("quality"),
    log:
        log_file("quality"),
    benchmark:
        benchmark_file("quality")
    threads: threads("quality")
    resources:
        **W.resources("quality"),
    params:
        cfg=W.step_cfg("quality"),
    script:
        "../scripts/quality.py"


# The study's claims at every target of the placement search (docs/placement_search.md):
# made by `snakemake -j2 placement_claims` only (~1 s of CPU per target), not by `figures`.
rule target_claims:
    input:
        placement=W.step_input("search"),
        code=W.code("target_claims"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("target_claims"),
    log:
        log_file("target_claims"),
    benchmark:
        benchmark_file("target_claims")
    threads: threads("target_claims")
    resources:
        **W.resources("target_claims"),
    params:
        cfg=W.step_cfg("target_claims"),
    script:
        "../scripts/target_claims.py"


rule summarise_target_claims:
    input:
        claims=W.step_inputs("target_claims", target="placement_claims"),
        code=W.code("summarise_target_claims"),
    output:
        **outputs("summarise_target_claims"),
    log:
        log_file("summarise_target_claims"),
    benchmark:
        benchmark_file("summarise_target_claims")
    threads: threads("summarise_target_claims")
    resources:
        **W.resources("summarise_target_claims"),
    script:
        "../scripts/summarise_target_claims.py"


# What blocks each synergy set where the full set succeeds (docs/blockers.md).
rule blockers:
    input:
        contacts=W.step_input("contacts"),
        gfo=W.step_input("optimise"),
        code=W.code("blockers"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("blockers"),
    log:
        log_file("blockers"),
    benchmark:
        benchmark_file("blockers")
    threads: threads("blockers")
    resources:
        **W.resources("blockers"),
    params:
        cfg=W.step_cfg("blockers"),
    script:
        "../scripts/blockers.py"


rule blockers_table:
    input:
        blockers=W.step_inputs("blockers"),
        code=W.code("blockers_table"),
    output:
        **outputs("blockers_table"),
    log:
        log_file("blockers_table"),
    benchmark:
        benchmark_file("blockers_table")
    threads: threads("blockers_table")
    resources:
        **W.resources("blockers_table"),
    params:
        cfg=W.step_cfg("blockers_table"),
    script:
        "../scripts/blockers_table.py"


# The incremental planner against the exhaustive search (docs/planner.md): made by
# `snakemake -j2 plans` (or `synergrasp plan OBJECT`), not by `figures`.
rule plan:
    input:
        contacts=W.step_input("contacts"),
        gfo=W.step_input("optimise"),
        code=W.code("plan"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("plan"),
    log:
        log_file("plan"),
    benchmark:
        benchmark_file("plan")
    threads: threads("plan")
    resources:
        **W.resources("plan"),
    params:
        cfg=W.step_cfg("plan"),
    script:
        "../scripts/plan.py"


rule objects_summary:
    input:
        success_rates=W.study_input("tables", "tables/success_rates.csv"),
        preservation=W.study_input("tables", "tables/minimum_preservation.csv"),
        graspable=W.study_input("realism", "tables/graspable_objects.csv"),
        plans=W.object_files("plan", "plan"),
        enrollment=W.object_files("plan", "enrollment"),
        manifest=W.random_objects_manifest,
        code=W.code("objects_summary"),
    output:
        **outputs("objects_summary"),
    log:
        log_file("objects_summary"),
    benchmark:
        benchmark_file("objects_summary")
    threads: threads("objects_summary")
    resources:
        **W.resources("objects_summary"),
    params:
        cfg=W.step_cfg("objects_summary"),
    script:
        "../scripts/objects_summary.py"
