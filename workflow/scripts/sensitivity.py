"""The sweep's summary: one row per scenario, and its two figures (docs/sensitivity.md)."""

import pandas as pd

from synergrasp.analysis.sensitivity import ScenarioTables, sensitivity_table, table2_long
from synergrasp.figures.sensitivity import figure_claims_grid, figure_table2_curves
from synergrasp.job_log import job_log
from synergrasp.table_contracts import write_study_table

with job_log(snakemake.log[0]):
    read = lambda kind: [pd.read_csv(p) for p in snakemake.input[kind]]  # noqa: E731
    scenarios = {
        name: ScenarioTables(claims, table2, rates, preservation, realism)
        for name, claims, table2, rates, preservation, realism in zip(
            snakemake.params.scenarios,
            read("claims"),
            read("table2"),
            read("success_rates"),
            read("preservation"),
            read("realism"),
        )
    }
    summary = sensitivity_table(scenarios)
    summary.insert(1, "placement", snakemake.params.placements)  # searched again or not (docs/sensitivity.md)
    write_study_table(summary, snakemake.output.csv, snakemake.output.md, title="Findings across the scenarios of the sweep")
    figure_claims_grid(summary, snakemake.output.grid_png, snakemake.output.grid_pdf)
    figure_table2_curves(table2_long(scenarios), snakemake.output.curves_png, snakemake.output.curves_pdf)
