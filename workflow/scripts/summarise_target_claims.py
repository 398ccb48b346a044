"""The claims over the placement search's targets, every object: a table and a figure."""

import pandas as pd

from synergrasp import table_contracts
from synergrasp.analysis.target_claims import claims_summary
from synergrasp.figures.placement_claims import figure_placement_claims
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    per_target = pd.concat(
        [table_contracts.read(table_contracts.TARGET_CLAIMS, p) for p in snakemake.input.claims], ignore_index=True
    )
    summary = claims_summary(per_target)
    table_contracts.write_study_table(
        summary,
        snakemake.output.csv,
        snakemake.output.md,
        title="The study's claims over the placement search's scored targets (% of targets)",
    )
    figure_placement_claims(summary, snakemake.output.png, snakemake.output.pdf)
