"""The incremental planner on one object against its exhaustive search (docs/planner.md)."""

from synergrasp import tables
from synergrasp.analysis.plan_study import PlanParams, plan_object
from synergrasp.figures.planner import figure_plan
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = PlanParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    contacts = tables.read(tables.CONTACTS, snakemake.input.contacts)
    gfo = tables.read(tables.GFO, snakemake.input.gfo)
    result = plan_object(contacts, gfo, load_synergies(params.synergies).matrix, params)
    out = snakemake.output
    tables.write_csv(tables.PLAN, result.table, out.plan)
    tables.write_csv(tables.ENROLLMENT, result.enrollment, out.enrollment)
    figure_plan(result.full, result.plans, result.table, result.enrollment, snakemake.wildcards.object, out.png, out.pdf)
