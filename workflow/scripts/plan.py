"""The incremental planner on one object against its exhaustive search (docs/planner.md)."""

from synergrasp import table_contracts
from synergrasp.analysis.plan_study import PlanParams, plan_object
from synergrasp.figures.planner import figure_plan
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = PlanParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    contacts = table_contracts.read(table_contracts.CONTACTS, snakemake.input.contacts)
    gfo = table_contracts.read(table_contracts.GFO, snakemake.input.gfo)
    result = plan_object(contacts, gfo, load_synergies(params.synergies).matrix, params)
    out = snakemake.output
    table_contracts.write_csv(table_contracts.PLAN, result.table, out.plan)
    table_contracts.write_csv(table_contracts.ENROLLMENT, result.enrollment, out.enrollment)
    figure_plan(result.full, result.plans, result.table, result.enrollment, snakemake.wildcards.object, out.png, out.pdf)
