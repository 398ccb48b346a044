"""Fig. 3: the workflow's own rule graph, drawn from `snakemake --rulegraph`."""
import subprocess
import sys
from contextlib import redirect_stderr

from synergrasp.figures import figure_rulegraph

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    command = [sys.executable, "-m", "snakemake", "-s", snakemake.params.snakefile, "--nolock",
               "--rulegraph", "figures", "--quiet", "all"]
    for path in snakemake.params.configfiles:
        command += ["--configfile", path]
    if snakemake.params.configfiles:
        command.append("--replace-workflow-config")
    dot = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    with open(snakemake.output.dot, "w") as handle:
        handle.write(dot)
    figure_rulegraph(dot, snakemake.output.png, snakemake.output.pdf)
