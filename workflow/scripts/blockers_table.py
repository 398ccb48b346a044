"""The study table and figure of what blocks each synergy set, from every object's blockers
table, read one object at a time."""

from synergrasp import table_contracts
from synergrasp.analysis.blockers import blocker_sets, blockers_summary_by_object
from synergrasp.figures.blockers import figure_blockers
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    summary = blockers_summary_by_object(snakemake.input.blockers, blocker_sets(snakemake.params.cfg["synergy_sets"]))
    table_contracts.write_study_table(
        summary,
        snakemake.output.csv,
        snakemake.output.md,
        title="What blocks each synergy set where the full set succeeds (% of failing poses)",
    )
    figure_blockers(summary, snakemake.output.png, snakemake.output.pdf)
