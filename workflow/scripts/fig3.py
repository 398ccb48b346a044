"""Fig. 3: the workflow's own rule graph, drawn from `snakemake --rulegraph`."""

import subprocess
import sys

from synergrasp.figures.fig3_rulegraph import canonical_rulegraph, figure_rulegraph
from synergrasp.file_output import replacing
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]) as log:
    command = [
        sys.executable,
        "-m",
        "snakemake",
        "figures",
        "-s",
        snakemake.input.snakefile,
        "--nolock",
        "--quiet",
        "all",
        "--rulegraph",
        "dot",
    ]
    command += ["--configfile", snakemake.params.configfile, "--replace-workflow-config"]
    run = subprocess.run(command, capture_output=True, text=True)
    log.write(run.stderr)
    run.check_returncode()
    dot = canonical_rulegraph(run.stdout)
    with replacing(snakemake.output.dot) as partial:
        partial.write_text(dot)
    figure_rulegraph(dot, snakemake.output.png, snakemake.output.pdf)
