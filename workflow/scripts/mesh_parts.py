"""The convex parts of one mesh file (docs/shapes.md), written where the shapes read them."""

from synergrasp.job_log import job_log
from synergrasp.simulation.shapes.convex_parts import write_parts
from synergrasp.simulation.shapes.mesh_file import read_mesh

with job_log(snakemake.log[0]):
    write_parts(read_mesh(snakemake.input.mesh), snakemake.output[0])
