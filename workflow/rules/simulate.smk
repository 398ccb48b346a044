# Stage 1: search each object's placement, close the hand on it at every pose, and select
# the contacts that count. Outputs, log, benchmark, threads and requests: synergrasp.steps.


# A mesh's convex parts, one job per mesh file (named by its content and the decomposition's
# parameters), before any job that builds its shape (W.user_files).
rule mesh_parts:
    input:
        code=W.code("mesh_parts"),
        mesh=W.mesh_file,
    output:
        **outputs("mesh_parts"),
    log:
        log_file("mesh_parts"),
    benchmark:
        benchmark_file("mesh_parts")
    threads: threads("mesh_parts")
    resources:
        **W.resources("mesh_parts"),
    script:
        "../scripts/mesh_parts.py"


rule search:
    input:
        code=W.code("search"),
        data=SHIPPED_DATA,
        user=W.user_files,
    output:
        **outputs("search"),
    log:
        log_file("search"),
    benchmark:
        benchmark_file("search")
    threads: threads("search")
    resources:
        **W.resources("search"),
    params:
        cfg=W.step_cfg("search"),
    script:
        "../scripts/search.py"


rule simulate:
    input:
        code=W.code("simulate"),
        data=SHIPPED_DATA,
        user=W.user_files,
        search=W.search_input(),
    output:
        **outputs("simulate"),
    log:
        log_file("simulate"),
    benchmark:
        benchmark_file("simulate")
    threads: threads("simulate")
    resources:
        **W.resources("simulate"),
    params:
        cfg=W.step_cfg("simulate"),
    script:
        "../scripts/simulate.py"


rule contacts:
    input:
        contacts=W.step_input("simulate"),
        code=W.code("contacts"),
    output:
        **outputs("contacts"),
    log:
        log_file("contacts"),
    benchmark:
        benchmark_file("contacts")
    threads: threads("contacts")
    resources:
        **W.resources("contacts"),
    params:
        cfg=W.step_cfg("contacts"),
    script:
        "../scripts/contacts.py"
