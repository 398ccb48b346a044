"""The study across its objects: one row per object and the distributions over objects."""

import pandas as pd

from synergrasp import table_contracts
from synergrasp.analysis.graspability import studied
from synergrasp.analysis.objects_summary import ObjectsSummaryParams, across_objects, object_rows
from synergrasp.figures.objects_summary import figure_objects_summary, figure_planner_tradeoff
from synergrasp.job_log import job_log
from synergrasp.simulation.random_objects import drawn_objects

with job_log(snakemake.log[0]):
    p = ObjectsSummaryParams.from_config(snakemake.params.cfg)
    inp, out = snakemake.input, snakemake.output
    plans = pd.concat([table_contracts.read_csv(table_contracts.PLAN, f) for f in inp.plans], ignore_index=True)
    enrollment = pd.concat([table_contracts.read_csv(table_contracts.ENROLLMENT, f) for f in inp.enrollment], ignore_index=True)
    rows = object_rows(
        pd.read_csv(inp.success_rates),
        pd.read_csv(inp.preservation),
        pd.read_csv(inp.graspable),
        plans,
        enrollment,
        p.n_full,
        p.hierarchy_first,
    )
    drawn = pd.DataFrame(
        [d.row() for d in drawn_objects(p.random_objects, manifest=inp.manifest[0])] if p.random_objects else [],
        columns=["name", "index", "path", "scale", "longest_side_mm", "problem"],
    )
    table_contracts.write_study_table(rows, out.csv, out.md, title="The study per object")
    table_contracts.write_study_table(
        across_objects(rows, p.quantities()),
        out.intervals_csv,
        out.intervals_md,
        title="Across objects (95 % intervals: bootstrap over objects)",
    )
    table_contracts.write_study_table(drawn, out.drawn_csv, out.drawn_md, title="Drawn meshes (problem: why left out)")
    figure_objects_summary(studied(rows), p.radii_deg, out.png, out.pdf)
    figure_planner_tradeoff(studied(rows), p.radii_deg, out.planner_tradeoff_png, out.planner_tradeoff_pdf)
