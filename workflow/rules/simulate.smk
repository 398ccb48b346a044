# Stage 1: close the hand on each object at every pose, and select the contacts that count.


rule search_placement:
    input:
        code=code("search_placement"),
        data=SHIPPED_DATA,
        user=user_files,
    output:
        "{root}/objects/{object}/placement.csv",
    log:
        "{root}/logs/search_placement/{object}.log",
    benchmark:
        "{root}/benchmarks/search_placement/{object}.tsv"
    threads: 2
    resources:
        mem_mb=mem_mb("search_placement"),
        runtime=runtime_min("search_placement"),
    params:
        cfg=step_cfg("search"),
    script:
        "../scripts/search_placement.py"


rule simulate_contacts:
    input:
        code=code("simulate_contacts"),
        data=SHIPPED_DATA,
        user=user_files,
        search=searched_input,
    output:
        "{root}/objects/{object}/contacts.parquet",
    log:
        "{root}/logs/simulate_contacts/{object}.log",
    benchmark:
        "{root}/benchmarks/simulate_contacts/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("simulate_contacts"),
        runtime=runtime_min("simulate_contacts"),
    params:
        cfg=step_cfg("simulate"),
    script:
        "../scripts/simulate_contacts.py"


rule select_contacts:
    input:
        contacts=step_input("simulate"),
        code=code("select_contacts"),
    output:
        "{root}/objects/{object}/load_carrying_contacts.parquet",
    log:
        "{root}/logs/select_contacts/{object}.log",
    benchmark:
        "{root}/benchmarks/select_contacts/{object}.tsv"
    threads: 1
    resources:
        mem_mb=mem_mb("select_contacts"),
        runtime=runtime_min("select_contacts"),
    params:
        cfg=step_cfg("contacts"),
    script:
        "../scripts/select_contacts.py"
