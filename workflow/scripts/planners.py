"""Planners compared at equal cost on every object of the scenario (docs/planner.md)."""

import pandas as pd

from synergrasp import table_contracts
from synergrasp.analysis.plan_study import PlannersParams, compare_on_study
from synergrasp.analysis.planners import across_objects, recommendation_line
from synergrasp.figures.planners import figure_planners
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    p = PlannersParams.from_config(snakemake.params.cfg)
    inp, out = snakemake.input, snakemake.output
    rows = []
    for contacts_path, gfo_path in zip(inp.contacts, inp.gfo):
        contacts = table_contracts.read(table_contracts.CONTACTS, contacts_path)
        minima = p.minima_for(str(contacts["object"].iat[0]))
        rows.append(compare_on_study(contacts, table_contracts.read(table_contracts.GFO, gfo_path), p.n_levels, minima))
    per_object = pd.concat(rows, ignore_index=True)
    across = across_objects(per_object)
    table_contracts.write_study_table(
        per_object[list(table_contracts.PLANNERS.names)], out.csv, out.md, title="Planners compared at equal cost, per object"
    )
    table_contracts.write_study_table(
        across[list(table_contracts.PLANNERS_ACROSS.names)],
        out.across_csv,
        out.across_md,
        title="Planners across the objects (recommended: the pre-registered rule's choice)",
    )
    print(recommendation_line(across))
    figure_planners(per_object, across, out.png, out.pdf)
