"""The study's tables from every object's optimisation results and local minima, read one
object at a time."""

import warnings

from synergrasp.analysis.invariants import InvariantWarning
from synergrasp.analysis.study_tables import object_loaders, study_tables
from synergrasp.analysis.summaries import NoSuccessWarning, TablesParams
from synergrasp.job_log import job_log
from synergrasp.table_contracts import PLANNERS, read_csv, write_study_table

with job_log(snakemake.log[0]) as log, warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", InvariantWarning)
    warnings.simplefilter("always", NoSuccessWarning)
    p = TablesParams.from_config(snakemake.params.cfg)
    planners = read_csv(PLANNERS, snakemake.input.planners)
    objects = object_loaders(snakemake.input.gfo, snakemake.input.minima)
    tables = study_tables(objects, p.synergy_sets, p.table2_k_max, p.settings, planners)
    for name, (title, table) in tables.items():
        write_study_table(table, snakemake.output[f"{name}_csv"], snakemake.output[f"{name}_md"], title=title)
    for warning in caught:  # the invariant checks on the console, everything in the log
        print(f"{warning.category.__name__}: {warning.message}", file=log)
        if issubclass(warning.category, (InvariantWarning, NoSuccessWarning)):
            print(f"WARNING: {warning.message}")
