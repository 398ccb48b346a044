"""Throughput of the pyramid friction cones in the study's loop: the compiled kernel (the
study's method, `gfo.FASTEST_METHOD["pyramid"] == "ipm"`) against PIQP per problem.

`optimise.optimise_grasps` with the strict test on the first `--grasps` grasps of
benchmarks/bench_gfo.py x the 75 study sets, for each pyramid model and the circular cone;
the PIQP runs set `FASTEST_METHOD["pyramid"]` to "piqp" for their duration. CPU time
(`time.process_time`), runs of the two methods interleaved, median of `--repeats`. Run on
one core with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1. Machine-read lines:
`pairs_per_cpu_s_<model>_<method>: N  (what)` (tools/measurements.py).
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace

import numpy as np
from bench_gfo import study_sets  # also puts tests/ (the generators) on the path
from grasp_problems import random_grasp, random_synergies

from synergrasp.config import defaults
from synergrasp.optimisation import gfo
from synergrasp.optimisation.problem import SynergySets
from synergrasp.optimisation.optimise import OptimiseParams, optimise_grasps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--grasps", type=int, default=40)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()

    # the grasps and synergies of bench_gfo.py (same seed, same draws)
    rng = np.random.default_rng(0)
    sets = study_sets()
    grasps = [random_grasp(rng, int(rng.integers(4, 13)), palm_contacts=int(rng.integers(0, 2))) for _ in range(200)]
    grasps = grasps[: args.grasps]
    synergies = SynergySets(random_synergies(rng), tuple(sets))
    base = replace(OptimiseParams.from_config(defaults(), "obj1").gfo, gravity_direction=(0.0, 0.0, -1.0))
    n = len(grasps) * len(sets)
    print(f"{n} (pose, set) pairs, mu = {base.mu}, strict test on; pairs per CPU second, median of {args.repeats}")
    study_method = gfo.FASTEST_METHOD["pyramid"]
    for model in ("pyramid4_inscribed", "pyramid8_inscribed", "pyramid8_circumscribed", "circular"):
        params = replace(base, friction_cone=model)
        methods = ("piqp", study_method) if params.cone.kind == "pyramid" else (gfo.FASTEST_METHOD["circular"],)
        optimise_grasps(grasps[:1], synergies, params)  # loads the compiled kernel
        rates: dict[str, list[float]] = {m: [] for m in methods}
        for _ in range(args.repeats):
            for method in methods:
                gfo.FASTEST_METHOD[params.cone.kind] = method
                try:
                    c0 = time.process_time()
                    out = optimise_grasps(grasps, synergies, params)
                    rates[method].append(n / (time.process_time() - c0))
                finally:
                    gfo.FASTEST_METHOD["pyramid"] = study_method
        fallback = float(np.mean(out["solver"] == "clarabel_fallback"))
        line = ", ".join(f"{m} {statistics.median(r):,.0f}" for m, r in rates.items())
        print(f"{model}: {line}; fallback share of the last method {fallback:.4f}")
        for method, rate in rates.items():
            print(
                f"pairs_per_cpu_s_{model}_{method}: {statistics.median(rate):.0f}  ({model}, {method}, (pose, set) "
                f"pairs per CPU second with the strict test, median of {args.repeats}, {n:,} pairs)"
            )


if __name__ == "__main__":
    main()
