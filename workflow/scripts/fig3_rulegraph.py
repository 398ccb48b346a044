"""Fig. 3: the workflow's own rule graph, drawn from `snakemake --rulegraph`."""
import subprocess
import sys
from contextlib import redirect_stderr

from synergrasp.figures.study_figures import figure_rulegraph

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    command = [sys.executable, "-m", "snakemake", "figures", "-s", snakemake.params.snakefile,
               "--nolock", "--quiet", "all", "--rulegraph", "dot"]
    command += ["--configfile", snakemake.params.configfile, "--replace-workflow-config"]
    run = subprocess.run(command, capture_output=True, text=True)
    log.write(run.stderr)
    run.check_returncode()
    dot = run.stdout
    with open(snakemake.output.dot, "w") as handle:
        handle.write(dot)
    figure_rulegraph(dot, snakemake.output.png, snakemake.output.pdf)
