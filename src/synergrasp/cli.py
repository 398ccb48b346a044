"""The ``synergrasp`` console command (docs/inspector.md).

    synergrasp grasp obj4 --alpha -30 --beta 0 [--configfile my.yaml] [--sets 1 1-5 1-15] [--json]
                     [--png grasp.png] [--html grasp.html [--forces 1-15]]

    synergrasp plan obj4 [--radius 10 20 30] [--configfile my.yaml] [--results results] [--csv plan.csv]

Bad arguments end with one line naming the argument and exit status 2.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["main", "format_inspection"]


def _read_overlays(paths: Sequence[str]) -> dict[str, Any]:
    """The configuration given by ``--configfile`` overlays, in order, on the study's defaults."""
    import yaml

    from synergrasp.config import overlay

    config: dict[str, Any] = {}
    for path in paths:
        try:
            with open(path, encoding="utf-8") as handle:
                config = overlay(config, yaml.safe_load(handle) or {})
        except OSError as err:
            raise SystemExit(f"synergrasp grasp: --configfile {path}: {err.strerror}") from None
    return config


def _number(value: float, digits: int = 3) -> str:
    return "—" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.{digits}g}"


#: The optimisation's status under the object's weight, in words.
_WEIGHT_WORDS = {"force_closure": "feasible", "infeasible": "infeasible", "rank_deficient": "rank(G) < 6",
                 "no_grasp": "no grasp", "numerical_failure": "solver failed"}


def format_inspection(result: Any) -> str:
    """The inspection as text: pose, contacts, quality indices, one line per synergy set."""
    from synergrasp.ids import set_name

    lines = [f"{result.object} at alpha = {result.alpha_deg:g} deg, beta = {result.beta_deg:g} deg (pose {result.pose}): "
             f"{result.closure_status}, {len(result.contacts)} contacts; weight {result.weight_N:.3g} N"]
    if len(result.contacts):
        lines.append(f"  {'link':<14} {'point (mm)':<28} inward normal")
        for row in result.contacts.itertuples():
            point = ", ".join(f"{v:7.2f}" for v in row.point_mm)
            normal = ", ".join(f"{v:6.3f}" for v in row.normal)
            lines.append(f"  {row.link_name:<14} ({point})  ({normal})")
    q = result.quality
    if q is not None:
        axes = ", ".join(_number(v) for v in q.manipulability if v > 0) or "none"
        lines.append(f"quality: rank(G) {q.rank_G}, sigma_min {_number(q.sigma_min)}, isotropy {_number(q.isotropy)}, "
                     f"Ferrari-Canny epsilon {_number(q.epsilon)} (fully actuated; torques / {q.torque_length_mm:.1f} mm); "
                     f"manipulability axes with all synergies: {axes}")
    if result.sets:
        lines.append(f"  {'set':<22} {'force closure':<14} {'under the weight':<17} {'force N':>9} {'/ weight':>9} "
                     f"{'e_s':>4} {'cone use':>9}")
        for s in result.sets:
            lines.append(f"  {set_name(s.synergies):<22} "
                         f"{'yes' if s.force_closure else 'no':<14} {_WEIGHT_WORDS.get(s.status, s.status):<17} "
                         f"{_number(s.force_N, 4):>9} {_number(s.force_N / result.weight_N, 3):>9} {s.e_s:>4} "
                         f"{'—' if math.isnan(s.cone_use) else f'{s.cone_use:.3f}':>9}")
    return "\n".join(lines)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="synergrasp", description="synergrasp: one grasp of the study in full")
    sub = parser.add_subparsers(dest="command", required=True)
    grasp = sub.add_parser("grasp", help="close the hand on one object at one pose and optimise its grasp")
    grasp.add_argument("object", help="an object of the configuration (obj1 … obj4 in the study)")
    grasp.add_argument("--alpha", type=float, required=True, help="alpha, deg (a grid value)")
    grasp.add_argument("--beta", type=float, required=True, help="beta, deg (a grid value)")
    grasp.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    grasp.add_argument("--sets", nargs="+", help="synergy sets: k, a-b (S_a..S_b) or a,b,c (default: each "
                                                 "single synergy and {S1..Sk} for every k)")
    grasp.add_argument("--results", default="results", help="where the study's outputs are (the searched "
                                                            "placement's target: <results>/objects/<object>/placement.csv)")
    grasp.add_argument("--json", action="store_true", help="print the result as JSON")
    grasp.add_argument("--png", metavar="PATH", help="write the grasp drawn as in Fig. 2 from two views (PNG)")
    grasp.add_argument("--html", metavar="PATH", help="write the grasp in 3-D, with the optimal contact forces of "
                                                      "one set as arrows, as one self-contained page")
    grasp.add_argument("--forces", metavar="SET", help="the set whose forces --html draws (default: the last set "
                                                       "asked, {S1..Sk} of every synergy by default)")
    plan = sub.add_parser("plan", help="the incremental planner on one object, against the study's exhaustive search "
                                       "(reads <results>/objects/<object>/contacts and gfo tables; docs/planner.md)")
    plan.add_argument("object", help="an object of the configuration")
    plan.add_argument("--radius", type=float, nargs="+", help="neighbourhood radii, deg (default: "
                                                              "analyses.planner_radii_deg)")
    plan.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    plan.add_argument("--results", default="results", help="where the study's outputs are")
    plan.add_argument("--csv", metavar="PATH", help="write the plan table (one row per radius) as CSV")
    return parser


def _plan(args: argparse.Namespace) -> int:
    """``synergrasp plan``: the planner at each radius, one line each."""
    from dataclasses import replace

    from synergrasp import tables
    from synergrasp.analysis.plan_study import PlanParams, plan_object
    from synergrasp.config import ConfigError, validate_config
    from synergrasp.hand.synergies import load_synergies

    folder = Path(args.results) / "objects" / args.object
    contacts_path = next((folder / f for f in ("load_carrying_contacts.parquet", "contacts.parquet")
                          if (folder / f).is_file()), folder / "contacts.parquet")
    try:
        cfg = validate_config(_read_overlays(args.configfile))
        if args.object not in cfg["objects"]:
            raise ConfigError(f"object {args.object!r} is not in the configuration ({', '.join(cfg['objects'])})")
        params = PlanParams.from_config(cfg, args.object)
        params = replace(params, radii_deg=tuple(args.radius)) if args.radius else params
        contacts = tables.read(tables.CONTACTS, contacts_path)
        gfo = tables.read(tables.GFO, folder / "gfo.parquet")
    except (ConfigError, ValueError, FileNotFoundError) as err:
        print(f"synergrasp plan: {err}", file=sys.stderr)
        return 2
    result = plan_object(contacts, gfo, load_synergies(params.synergies).matrix, params)
    for row in result.table.itertuples():
        print(f"{row.object} radius {row.radius_deg:g} deg: {row.n_solves} of {row.n_exhaustive_solves} solves "
              f"({row.solve_share_percent:.1f} %), pose {row.best_pose} (alpha {row.best_alpha_deg:g}, beta "
              f"{row.best_beta_deg:g}) force {_number(row.best_force_N, 4)} N, exhaustive minimum "
              f"{_number(row.exhaustive_min_force_N, 4)} N, rank {row.rank} of {row.n_ranked}, regret "
              f"{_number(row.regret_percent, 3)} %")
    if args.csv:
        tables.write_csv(tables.PLAN, result.table, args.csv)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command; 0 on success, 2 on a bad argument (one line on standard error)."""
    args = _parser().parse_args(argv)
    if args.command == "plan":
        return _plan(args)
    from synergrasp.config import ConfigError
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.inspector import InspectionError, inspect_grasp, parse_sets

    config = _read_overlays(args.configfile)
    try:
        sets, forces = None, None
        if args.sets or args.forces:
            from synergrasp.config import validate_config
            from synergrasp.inspector import default_sets

            cfg = validate_config(config)
            n = load_synergies(cfg["synergies"], joint_names=load_hand(cfg["hand"]).joint_names).matrix.shape[1]
            sets = parse_sets(args.sets, n) if args.sets else default_sets(n)
            if args.forces:
                (forces,) = parse_sets([args.forces], n, "--forces")
                sets += [forces] if forces not in sets else []
        result = inspect_grasp(config, args.object, args.alpha, args.beta, sets, args.results)
    except (InspectionError, ConfigError) as err:
        print(f"synergrasp grasp: {err}", file=sys.stderr)
        return 2
    print(json.dumps(result.to_dict(), indent=1) if args.json else format_inspection(result))
    if args.png:
        from synergrasp.inspector import grasp_picture

        grasp_picture(result, args.png)
        if not args.json:
            print(f"picture: {args.png}")
    if args.html:
        from synergrasp.figures.grasp_3d import grasp_page
        from synergrasp.inspector import grasp_view

        Path(args.html).write_text(grasp_page(grasp_view(result, forces)), encoding="utf-8")
        if not args.json:
            print(f"3-D page: {args.html}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
