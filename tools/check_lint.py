"""`snakemake --lint` must report nothing but its advice to give every rule a conda
environment or container: this workflow installs its software from the hashed pip lock
(environment.lock) instead, the same environment for every rule.

    python tools/check_lint.py      exit 1 (and the lints) when any other lint is found
"""

import re
import subprocess
import sys
from pathlib import Path

ACCEPTED = {"Specify a conda environment or container for each rule."}
ROOT = Path(__file__).resolve().parents[1]


def lints() -> tuple[list[str], str]:
    """Titles of the lints Snakemake reports on this workflow, and its full output."""
    run = subprocess.run(
        [sys.executable, "-m", "snakemake", "--lint", "-s", str(ROOT / "Snakefile"), "--directory", str(ROOT)],
        capture_output=True,
        text=True,
    )
    text = run.stdout + run.stderr
    if "Traceback" in text or "Error" in text.split("Lints for", 1)[0]:
        sys.exit(f"snakemake --lint did not run:\n{text}")
    return re.findall(r"^    \* (.+):$", text, flags=re.MULTILINE), text


if __name__ == "__main__":
    titles, text = lints()
    others = [t for t in titles if t not in ACCEPTED]
    if others:
        print(text)
        sys.exit(f"snakemake --lint: {len(others)} lint(s) besides the conda/container advice: {others}")
    print(f"snakemake --lint: clean except the conda/container advice ({len(titles)} rules)")
