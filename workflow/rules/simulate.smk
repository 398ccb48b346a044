# Stage 1: close the hand on each object at every pose, and select the contacts that count.


rule simulate_contacts:
    input:
        code=code("simulate_contacts"),
        data=SHIPPED_DATA,
        user=user_files,
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
