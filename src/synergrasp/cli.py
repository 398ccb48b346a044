"""The ``synergrasp`` console command (docs/inspector.md).

    synergrasp grasp obj4 --alpha -30 --beta 0 [--configfile my.yaml] [--sets 1 1-5 1-15] [--json]
                     [--png grasp.png] [--html grasp.html [--forces 1-15]]
    synergrasp synergies fit POSTURES.csv --out synergies.csv [--synergies K] [--png variance.png]
    synergrasp synergies map HAND --out synergies.csv [--table TABLE] [--source SOURCE_HAND] [--synergies K]
                             [--postures postures.csv] [--png variance.png]
    synergrasp synergies map HAND --out synergies.csv --joint-mapping MAPPING.yaml
    synergrasp hand show [HAND] [--synergies TABLE] [--png hand.png] [--count K]

Bad input (an argument, a configuration file, the hand or synergy file it names, an output
path that cannot be written, a count below 1, a radius that is not a positive number, an
output that names a file the command reads: symbolic and hard links included) ends with one
line per problem naming the argument, the file or the key, and exit status 2, before any
work, for every command: the configuration goes through the workflow's own checks
(``synergrasp.input_checks``). Warnings on the configuration are printed too.

    synergrasp plan obj4 [--radius 10 20 30] [--configfile my.yaml] [--results results] [--csv plan.csv]
    synergrasp plan obj4 --on-demand [--planner random_1200] [--seed 0] [--csv plan.csv]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

__all__ = ["main", "format_inspection"]


def _number(value: float, digits: int = 3) -> str:
    return "—" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.{digits}g}"


#: The grasp's opposition (docs/opposition.md), in words.
_OPPOSITION_WORDS = {
    "palm": "held against the palm: a power grasp",
    "pad": "between the thumb's and the fingers' pads: a precision grip",
    "side": "thumb pad against the side of the index: a lateral pinch",
    "none": "no two contact groups push against each other",
}

#: The optimisation's status under the object's weight, in words.
_WEIGHT_WORDS = {
    "feasible": "feasible",
    "infeasible": "infeasible",
    "rank_deficient": "rank(G) < 6",
    "no_grasp": "no grasp",
    "numerical_failure": "solver failed",
}


def format_inspection(result: Any) -> str:
    """The inspection as text: pose, contacts, quality indices, one line per synergy set."""
    from synergrasp.ids import set_name

    lines = [
        f"{result.object} at alpha = {result.alpha_deg:g} deg, beta = {result.beta_deg:g} deg (pose {result.pose}): "
        f"{result.closure_status}, {len(result.contacts)} contacts; weight {result.weight_N:.3g} N; "
        f"opposition: {result.opposition} ({_OPPOSITION_WORDS[result.opposition]})"
    ]
    if len(result.contacts):
        lines.append(f"  {'link':<14} {'point (mm)':<28} {'inward normal':<23} face        on")
        for row in result.contacts.itertuples():
            point = ", ".join(f"{v:7.2f}" for v in row.point_mm)
            normal = ", ".join(f"{v:6.3f}" for v in row.normal)
            lines.append(f"  {row.link_name:<14} ({point})  ({normal})  {row.face:<11} {row.feature}")
    q = result.quality
    if q is not None:
        axes = ", ".join(_number(v) for v in q.manipulability if v > 0) or "none"
        lines.append(
            f"quality: rank(G) {q.rank_G}, sigma_min {_number(q.sigma_min)}, isotropy {_number(q.isotropy)}, "
            f"Ferrari-Canny epsilon {_number(q.epsilon)} (fully actuated; torques / {q.torque_length_mm:.1f} mm); "
            f"manipulability axes with all synergies: {axes}"
        )
    if result.sets:
        lines.append(
            f"  {'set':<22} {'force closure':<14} {'under the weight':<17} {'force N':>9} {'/ weight':>9} "
            f"{'e_s':>4} {'cone use':>9}"
        )
        for s in result.sets:
            lines.append(
                f"  {set_name(s.synergies):<22} "
                f"{'yes' if s.force_closure else 'no':<14} {_WEIGHT_WORDS.get(s.status, s.status):<17} "
                f"{_number(s.force_N, 4):>9} {_number(s.force_N / result.weight_N, 3):>9} {s.e_s:>4} "
                f"{'—' if math.isnan(s.cone_use) else f'{s.cone_use:.3f}':>9}"
            )
        lines += _blocker_lines(result.sets)
    return "\n".join(lines)


#: Why a set fails when no contact is named (docs/blockers.md).
_REASON_WORDS = {
    "no_internal_force": "no internal force (e_s = 0)",
    "rank_deficient": "rank(G) < 6",
    "no_squeeze": "every internal force it reaches has zero total normal force",
    "numerical_failure": "the max-margin problem was not solved",
}


def _blocker_lines(sets: Any) -> list[str]:
    """What blocks each set not in force closure (docs/blockers.md)."""
    from synergrasp.ids import set_name

    failing = [s for s in sets if getattr(s, "blocked_by", "")]
    if not failing:
        return []
    lines = ["what blocks each set not in force closure (t*: best least cone margin, per N of total normal force):"]
    for s in failing:
        if s.blocked_by != "contacts":
            lines.append(f"  {set_name(s.synergies):<22} {_REASON_WORDS.get(s.blocked_by, s.blocked_by)}")
            continue
        lines.append(f"  {set_name(s.synergies):<22} t* = {s.margin:.3g}")
        for b in s.blockers:
            article = "an" if b.feature == "edge" else "a"
            lines.append(
                f"    contact {b.contact}: {b.link_name} ({b.link_kind}), {b.face} on {article} {b.feature}, "
                f"normal force {b.normal_force:+.3g}, {_number(b.angle_outside_deg)} deg outside its cone"
            )
    return lines


def _parser() -> argparse.ArgumentParser:
    from synergrasp.steps import RESULTS

    parser = argparse.ArgumentParser(prog="synergrasp", description="synergrasp: one grasp of the study in full")
    sub = parser.add_subparsers(dest="command", required=True)
    grasp = sub.add_parser("grasp", help="close the hand on one object at one pose and optimise its grasp")
    grasp.add_argument("object", help="an object of the configuration (obj1 … obj4 in the study)")
    grasp.add_argument("--alpha", type=float, required=True, help="alpha, deg (a grid value)")
    grasp.add_argument("--beta", type=float, required=True, help="beta, deg (a grid value)")
    grasp.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    grasp.add_argument(
        "--sets",
        nargs="+",
        help="synergy sets: k, a-b (S_a..S_b) or a,b,c (default: each single synergy and {S1..Sk} for every k)",
    )
    grasp.add_argument(
        "--results",
        default=RESULTS,
        help="where the study's outputs are (the searched placement's target: <results>/objects/<object>/placement.csv)",
    )
    grasp.add_argument("--json", action="store_true", help="print the result as JSON")
    grasp.add_argument("--png", metavar="PATH", help="write the grasp drawn as in Fig. 2 from two views (PNG)")
    grasp.add_argument(
        "--html",
        metavar="PATH",
        help="write the grasp in 3-D, with the optimal contact forces of one set as arrows, as one self-contained page",
    )
    grasp.add_argument(
        "--forces",
        metavar="SET",
        help="the set whose forces --html draws (default: the last set asked, {S1..Sk} of every synergy by default)",
    )
    synergies = sub.add_parser("synergies", help="synergy tables").add_subparsers(dest="action", required=True)
    fit = synergies.add_parser("fit", help="fit a synergy table to postures (principal components, docs/synergies.md)")
    fit.add_argument("postures", help="CSV: one column per joint, one row per posture, rad")
    fit.add_argument("--out", required=True, help="the synergy table to write (joint, mean_rad, syn1..synK)")
    fit.add_argument("--synergies", type=int, help="how many synergies to keep (default: all with variance)")
    fit.add_argument("--png", metavar="PATH", help="write the explained variance per synergy (PNG)")
    mapping = synergies.add_parser(
        "map",
        help="carry a synergy table over to another hand in the object's terms: "
        "fingertips and thumb-to-fingertip vectors retargeted, then principal "
        "components (docs/synergies.md)",
    )
    mapping.add_argument("hand", help="the target hand: a hand file or description, or a shipped hand (shadow_hand)")
    mapping.add_argument("--out", required=True, help="the target hand's synergy table to write (CSV)")
    mapping.add_argument("--table", help="the source hand's synergy table (name or CSV; default: the study's, softhand_opposed)")
    mapping.add_argument("--source", help="the source hand (a hand file or description; default: the study's hand)")
    mapping.add_argument("--synergies", type=int, help="how many synergies to keep (default: as many as the table has)")
    mapping.add_argument(
        "--postures",
        metavar="PATH",
        help="also write the mapped postures (CSV, one column per joint: the input of synergies fit)",
    )
    mapping.add_argument("--png", metavar="PATH", help="write the explained variance per synergy (PNG)")
    mapping.add_argument(
        "--joint-mapping",
        metavar="YAML",
        help="map the human synergies joint by joint with this "
        "mapping file instead (for hands whose joints "
        "correspond; docs/synergies.md)",
    )
    hands = sub.add_parser("hand", help="hands").add_subparsers(dest="action", required=True)
    show = hands.add_parser("show", help="print a hand's joints; draw it at its mean posture and along each synergy")
    show.add_argument(
        "hand",
        nargs="?",
        help="a hand file or description, or a shipped hand: shadow_hand, inspire_hand (default: the study's hand)",
    )
    show.add_argument("--synergies", help="a synergy table (name or CSV; default: the shipped one, or a shipped hand's own)")
    show.add_argument("--png", metavar="PATH", help="write the hand at q_m + sigma S_k, sigma = -1, 0, +1 (PNG)")
    show.add_argument("--count", type=int, default=7, help="synergies drawn (default 7)")
    show.add_argument(
        "--closing-png", metavar="PATH", help="write the hand closing along S1 from the palm side and from the thumb side (PNG)"
    )
    plan = sub.add_parser(
        "plan",
        help="the incremental planner on one object, against the study's exhaustive search "
        "(reads <results>/objects/<object>/contacts and gfo tables; docs/planner.md)",
    )
    plan.add_argument("object", help="an object of the configuration")
    plan.add_argument("--radius", type=float, nargs="+", help="neighbourhood radii, deg (default: analyses.planner_radii_deg)")
    plan.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    plan.add_argument("--results", default=RESULTS, help="where the study's outputs are")
    plan.add_argument("--csv", metavar="PATH", help="write the plan table (one row per radius; on demand: one row) as CSV")
    plan.add_argument(
        "--on-demand",
        action="store_true",
        help="close the hand only where the planner asks (the default for an object without the study's tables)",
    )
    plan.add_argument(
        "--planner", help="on demand: a candidate planner of docs/planner.md (default: the one the pre-registered rule selects)"
    )
    plan.add_argument("--seed", type=int, default=0, help="on demand: seed of a randomised planner (default 0)")
    return parser


#: Each command's output options: (option, attribute, the suffixes its file name may end in).
_OUTPUTS: dict[str, tuple[tuple[str, str, tuple[str, ...]], ...]] = {
    "grasp": (("--png", "png", (".png",)), ("--html", "html", (".html", ".htm"))),
    "synergies fit": (("--out", "out", (".csv",)), ("--png", "png", (".png",))),
    "synergies map": (("--out", "out", (".csv",)), ("--postures", "postures", (".csv",)), ("--png", "png", (".png",))),
    "hand show": (("--png", "png", (".png",)), ("--closing-png", "closing_png", (".png",))),
    "plan": (("--csv", "csv", (".csv",)),),
}


def _command(args: argparse.Namespace) -> str:
    """The command's name as its messages give it (``synergies fit``, ``grasp``)."""
    return " ".join(filter(None, (args.command, getattr(args, "action", None))))


def _inputs(args: argparse.Namespace) -> list[tuple[str, str]]:
    """(how the command names it, path) of every file the command reads that a user names."""
    named = [("--configfile", path) for path in getattr(args, "configfile", [])]
    if _command(args) == "synergies fit":
        named.append(("POSTURES", args.postures))
    if _command(args) == "synergies map":
        named += [
            (what, path)
            for what, path in (
                ("HAND", args.hand),
                ("--table", args.table),
                ("--source", args.source),
                ("--joint-mapping", args.joint_mapping),
            )
            if path is not None and Path(path).suffix
        ]
    if _command(args) == "hand show":
        from synergrasp.hand.description import SHIPPED_HANDS

        named += [
            (what, path)
            for what, path in (("HAND", args.hand), ("--synergies", args.synergies))
            if path is not None and path not in SHIPPED_HANDS and Path(path).suffix
        ]
    if args.command == "plan":
        folder = Path(args.results) / "objects" / args.object
        named += [
            ("--results", str(folder / name)) for name in ("contacts.parquet", "load_carrying_contacts.parquet", "gfo.parquet")
        ]
    return named


def _same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file: equal once resolved (symbolic links followed), or
    one file under two names (a hard link)."""
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and a.samefile(b))
    except OSError:
        return False


def _output_problems(args: argparse.Namespace) -> list[str]:
    """What keeps an output option from being written, one line each, before any work: a
    file name without the option's suffix, a folder, a folder missing or not writable, a
    file the command reads (its input is never its output)."""
    problems = []
    for option, attribute, suffixes in _OUTPUTS.get(_command(args), ()):
        path = getattr(args, attribute)
        if path is None:
            continue
        target = Path(path)
        folder = target.parent
        read = next((f"{what} {given}" for what, given in _inputs(args) if _same_file(target, Path(given))), None)
        if read is not None:
            problems.append(f"{option} {path}: is the file the command reads ({read}); write to another file")
        elif target.is_dir():
            problems.append(f"{option} {path}: is a folder; give a file name")
        elif target.suffix.lower() not in suffixes:
            problems.append(f"{option} {path}: the file name must end in {' or '.join(suffixes)}")
        elif not folder.is_dir():
            problems.append(f"{option} {path}: folder '{folder}' is not an existing folder")
        else:
            try:  # a file written and removed in that folder: permissions, a read-only disk
                with tempfile.NamedTemporaryFile(dir=folder, prefix=f".{target.name}."):
                    pass
            except OSError as err:
                problems.append(f"{option} {path}: folder '{folder}' cannot be written ({err.strerror or err})")
    return problems


def _count_problems(args: argparse.Namespace) -> list[str]:
    """Counts, radii and folders a command cannot use, one line each: a count below 1, a
    radius that is not a positive finite number (deg), a file given as ``--results``."""
    problems = []
    for option, attribute in (("--count", "count"), ("--synergies", "synergies")):
        value = getattr(args, attribute, None)
        if isinstance(value, int) and value < 1:
            problems.append(f"{option} {value}: must be a whole number of at least 1")
    bad = [r for r in getattr(args, "radius", None) or () if not (math.isfinite(r) and r > 0)]
    if bad:
        problems.append(f"--radius {' '.join(f'{r:g}' for r in bad)}: each radius must be a positive finite number of degrees")
    results = getattr(args, "results", None)
    if results is not None and Path(results).exists() and not Path(results).is_dir():
        problems.append(f"--results {results}: is a file; give the folder of the study's outputs")
    return problems


def _configuration(args: argparse.Namespace) -> dict[str, Any]:
    """The configuration of ``--configfile`` overlays as the workflow has it, drawn objects
    included (``input_checks.overlays_with_drawn_objects``)."""
    from synergrasp.input_checks import overlays_with_drawn_objects

    return overlays_with_drawn_objects(args.configfile)


def _plan(args: argparse.Namespace) -> int:
    """``synergrasp plan``: the planner at each radius, one line each."""
    from dataclasses import replace

    from synergrasp import table_contracts
    from synergrasp.analysis.plan_study import PlanParams, plan_object
    from synergrasp.config import ConfigError
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.input_checks import checked_scenario, unknown_object
    from synergrasp.steps import object_file

    try:
        cfg, warnings = checked_scenario(_configuration(args))
        for warning in warnings:
            print(f"synergrasp plan: warning: {warning}", file=sys.stderr)
        if unknown_object(cfg, args.object):
            raise ConfigError(unknown_object(cfg, args.object))
        params = PlanParams.from_config(cfg, args.object)
        # the files the workflow's rules read for this configuration, not whichever exists
        contacts_path = Path(object_file(cfg, "contacts", args.object, args.results))
        gfo_path = Path(object_file(cfg, "optimise", args.object, args.results))
        on_demand = args.on_demand or not gfo_path.is_file()
        if on_demand:
            demand = _on_demand_inputs(args, cfg)
        elif args.planner is not None or args.seed != 0:
            raise ValueError(
                "--planner and --seed: only with --on-demand (the study's tables are there: the "
                "incremental planner runs on them at each --radius)"
            )
        else:
            params = replace(params, radii_deg=tuple(args.radius)) if args.radius else params
            contacts = table_contracts.read(table_contracts.CONTACTS, contacts_path)
            gfo = table_contracts.read(table_contracts.GFO, gfo_path)
    except (ConfigError, ValueError, FileNotFoundError) as err:
        print(f"synergrasp plan: {err}", file=sys.stderr)
        return 2
    if on_demand:
        return _plan_on_demand(args, params, *demand, contacts_path, gfo_path)
    result = plan_object(contacts, gfo, load_synergies(params.synergies).matrix, params)
    for row in result.table.itertuples():
        print(
            f"{row.object} radius {row.radius_deg:g} deg: {row.n_solves} of {row.n_exhaustive_solves} solves "
            f"({row.solve_share_percent:.1f} %), pose {row.best_pose} (alpha {row.best_alpha_deg:g}, beta "
            f"{row.best_beta_deg:g}) force {_number(row.best_force_N, 4)} N, exhaustive minimum "
            f"{_number(row.exhaustive_min_force_N, 4)} N, rank {row.rank} of {row.n_ranked}, regret "
            f"{_number(row.regret_percent, 3)} %"
        )
    if args.csv:
        with _writing("--csv", args.csv):
            table_contracts.write_csv(table_contracts.PLAN, result.table, args.csv)
    return 0


def _on_demand_inputs(args: argparse.Namespace, cfg: dict) -> tuple[Any, Any, Any]:
    """The planner, ``close(poses)`` and the pose grid of ``synergrasp plan --on-demand``; each
    bad argument a ValueError naming it, before any closure."""
    from synergrasp.analysis.plan_new import DEFAULT_PLANNER, planner_spec
    from synergrasp.inspector import object_closure

    spec = planner_spec(args.planner or DEFAULT_PLANNER)
    if args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.radius:
        raise ValueError("--radius: only for the incremental planner on the study's tables (not on demand)")
    return (spec, *object_closure(cfg, args.object, args.results))


def _plan_on_demand(
    args: argparse.Namespace, params: Any, spec: Any, close: Any, grid: Any, contacts_path: Path, gfo_path: Path
) -> int:
    """``synergrasp plan --on-demand``: the chosen planner closing the hand only where it asks;
    against the study's exhaustive minimum where the study's tables are there."""
    import numpy as np
    import pandas as pd

    from synergrasp import table_contracts
    from synergrasp.analysis.plan_new import plan_on_demand
    from synergrasp.analysis.plan_study import replay_oracle
    from synergrasp.analysis.planner import pose_against_exhaustive
    from synergrasp.hand.synergies import load_synergies

    study = gfo_path.is_file() and contacts_path.is_file()
    matrix = load_synergies(params.synergies).matrix
    plan, _ = plan_on_demand(args.object, grid, close, matrix, params, spec, args.seed)
    least, regret = float("nan"), float("nan")
    if study:  # the study's exhaustive minimum over the same grid
        contacts, gfo = (
            table_contracts.read(table_contracts.CONTACTS, contacts_path),
            table_contracts.read(table_contracts.GFO, gfo_path),
        )
        full = replay_oracle(contacts, gfo, params.n_levels, params.minima)()
        order = np.argsort(contacts["pose"].to_numpy())
        versus = pose_against_exhaustive(plan.pose, plan.force_N, full.success[-1][order], full.force[-1][order])
        least, regret = versus["exhaustive_min_force_N"], 100.0 * (versus["regret"] - 1.0)
    print(
        f"{plan.object} on demand, planner {plan.planner}"
        + (f" (seed {plan.seed})" if spec.randomised else "")
        + f": pose {plan.pose} (alpha {plan.alpha_deg:g}, beta {plan.beta_deg:g}) force {_number(plan.force_N, 4)} N; "
        f"{plan.closures} of {plan.n_poses} closures ({100.0 * plan.closures / plan.n_poses:.1f} %), "
        f"{plan.problems} problems, {plan.wall_s:.1f} s"
        + (f"; the study's exhaustive minimum {_number(least, 4)} N, regret {_number(regret, 3)} %" if study else "")
    )
    if args.csv:
        row = vars(plan) | {"exhaustive_min_force_N": least, "regret_percent": regret}
        table_contracts.write_csv(table_contracts.PLAN_ON_DEMAND, pd.DataFrame([row]), args.csv)
    return 0


def _show_hand(args: argparse.Namespace) -> int:
    """``synergrasp hand show``: the joints (limits, mean posture, S1), links and fingertips."""
    from synergrasp.hand.checks import check_hand
    from synergrasp.hand.description import SHIPPED_HANDS
    from synergrasp.hand.kinematics import fingertip_positions
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.simulation.thumb_check import opposition_line

    problems: list[str] = []
    try:
        hand, _, warnings = check_hand(args.hand)
        table = args.synergies or (args.hand if args.hand in SHIPPED_HANDS else None)
        synergies = load_synergies(table, joint_names=hand.joint_names)
    except ValueError as err:
        problems += str(err).splitlines()
    if problems:
        print("\n".join(f"synergrasp hand show: {line}" for line in problems), file=sys.stderr)
        return 2
    for warning in warnings:
        print(f"synergrasp hand show: warning: {warning}", file=sys.stderr)
    deg = math.degrees
    print(
        f"{hand.name} ({hand.source}): {hand.n_joints} joints, {hand.n_links} links "
        f"({len(hand.shapeless_links)} without shape), {synergies.n_synergies} synergies"
    )
    print(f"{'joint':<15} {'lower':>7} {'upper':>7} {'mean':>7} {'S1':>8}   (deg; S1 rad per unit sigma)")
    for j, name in enumerate(hand.joint_names):
        print(
            f"{name:<15} {deg(hand.lower[j]):7.1f} {deg(hand.upper[j]):7.1f} {deg(synergies.mean[j]):7.1f} "
            f"{synergies.matrix[j, 0]:8.3f}"
        )
    tips = fingertip_positions(hand, synergies.mean)
    print(
        "fingertips at the mean posture (palm frame, mm): "
        + "; ".join(
            f"{hand.link_finger[link]} ({', '.join(f'{v:.1f}' for v in tip)})" for link, tip in zip(hand.fingertip_link, tips)
        )
    )
    if args.png:
        from synergrasp.figures.fig1_fig2_postures_grasps import figure_synergy_postures

        with _writing("--png", args.png):
            figure_synergy_postures(hand, synergies, args.png, None, n_synergies=min(args.count, synergies.n_synergies))
        print(f"picture: {args.png}")
    line, sigmas = opposition_line(hand, synergies)
    print(line)
    if args.closing_png:
        from synergrasp.figures.fig1_fig2_postures_grasps import figure_closing_views

        figure_closing_views(hand, synergies, args.closing_png, None, sigmas)
        print(f"closing along S1, palm side and thumb side: {args.closing_png}")
    return 0


def _map_synergies(args: argparse.Namespace) -> int:
    """``synergrasp synergies map``: every argument checked, then the mapping, the table
    written, the variance explained and the thumb-opposition check printed."""
    import numpy as np

    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies, resolve_synergies, write_synergies
    from synergrasp.hand.synergy_map import map_synergies
    from synergrasp.simulation.thumb_check import opposition_line

    if args.joint_mapping:
        return _map_joint_by_joint(args)
    problems: list[str] = []
    try:
        target = load_hand(args.hand)
        source = load_hand(args.source)
        table_path = resolve_synergies(args.table)
        table = load_synergies(table_path, joint_names=source.joint_names)
    except ValueError as err:
        problems += str(err).splitlines()
        target = table_path = None
    outputs = {
        option: Path(path) for option, path in (("--out", args.out), ("--postures", args.postures), ("--png", args.png)) if path
    }
    for option, path in outputs.items():
        if table_path is not None and path.resolve() == Path(table_path).resolve():
            problems.append(f"{option} {path}: is the input table; give another file name")
    if "--postures" in outputs and outputs["--postures"].resolve() == outputs["--out"].resolve():
        problems.append(f"--postures {args.postures}: is the --out file; give another file name")
    k_max = None if target is None else min(table.n_synergies, target.n_joints)
    if args.synergies is not None and k_max is not None and not 1 <= args.synergies <= k_max:
        problems.append(f"--synergies {args.synergies}: must be 1 … {k_max} (the table's columns, at most the target's joints)")
    if problems:
        print("\n".join(f"synergrasp synergies map: {line}" for line in problems), file=sys.stderr)
        return 2
    fit, mapped = map_synergies(source, table, target, args.synergies)
    write_synergies(fit.synergies, args.out)
    if args.postures:
        import pandas as pd

        pd.DataFrame(mapped.target, columns=list(target.joint_names)).to_csv(
            args.postures, index=False, float_format="%.17g", lineterminator="\n"
        )
    print(
        f"{target.name}: {len(mapped.sigma)} postures mapped from {source.name}'s table {table_path} "
        f"(fingertip and thumb-to-fingertip residual, RMS mm: median {np.median(mapped.residual_mm):.2f}, "
        f"max {np.max(mapped.residual_mm):.2f})"
    )
    _print_variance(fit)
    print(f"synergy table: {args.out}" + (f"; mapped postures: {args.postures}" if args.postures else ""))
    print(opposition_line(target, fit.synergies)[0])
    if args.png:
        from synergrasp.figures.synergy_fit import figure_explained_variance

        figure_explained_variance(fit, args.png)
        print(f"explained variance: {args.png}")
    return 0


def _map_joint_by_joint(args: argparse.Namespace) -> int:
    """``synergrasp synergies map --joint-mapping``: the human table mapped joint by joint
    (``map_human_synergies``), written, and the thumb-opposition check printed."""
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_human_synergies, load_synergy_mapping, map_human_synergies, write_synergies
    from synergrasp.simulation.thumb_check import opposition_line

    problems = [
        f"{option}: not used with --joint-mapping (it maps the human table joint by joint)"
        for option, value in (
            ("--table", args.table),
            ("--source", args.source),
            ("--synergies", args.synergies),
            ("--postures", args.postures),
            ("--png", args.png),
        )
        if value is not None
    ]
    try:
        target = load_hand(args.hand)
        table = map_human_synergies(load_human_synergies(), load_synergy_mapping(args.joint_mapping), target.joint_names)
    except (ValueError, KeyError, TypeError) as err:  # a mapping file's missing or malformed field
        problems.append(f"--joint-mapping {args.joint_mapping}: {err}")
    if problems:
        print("\n".join(f"synergrasp synergies map: {line}" for line in problems), file=sys.stderr)
        return 2
    write_synergies(table, args.out)
    print(f"{target.name}: the human synergies mapped joint by joint ({args.joint_mapping}); synergy table: {args.out}")
    print(opposition_line(target, table)[0])
    return 0


def _print_variance(fit: Any) -> None:
    """Per synergy: its variance, its share of the total and the cumulated share."""
    print(f"{'synergy':<8} {'variance (rad^2)':>17} {'explained':>10} {'cumulative':>11}")
    for i, (v, e, c) in enumerate(zip(fit.variance_rad2, fit.explained, fit.cumulative), start=1):
        print(f"S{i:<7} {v:>17.6g} {100 * e:>9.2f}% {100 * c:>10.2f}%")


def _fit_synergies(args: argparse.Namespace) -> int:
    """``synergrasp synergies fit``: the table, and the variance explained printed (and drawn)."""
    from synergrasp.hand.synergies import SynergyFileError, write_synergies
    from synergrasp.hand.synergy_fit import fit_synergies, read_postures

    try:
        names, postures = read_postures(args.postures)
        k_max = min(len(names), len(postures) - 1)
        if args.synergies is not None and args.synergies > k_max:
            raise ValueError(f"--synergies {args.synergies}: at most {k_max} for {len(postures)} postures of {len(names)} joints")
        fit = fit_synergies(names, postures, args.synergies)
    except (SynergyFileError, ValueError) as err:
        print(f"synergrasp synergies fit: {err}", file=sys.stderr)
        return 2
    with _writing("--out", args.out):
        write_synergies(fit.synergies, args.out)
    print(f"{len(postures)} postures of {len(names)} joints: total variance {fit.total_variance_rad2:.6g} rad^2")
    _print_variance(fit)
    print(f"synergy table: {args.out}")
    if args.png:
        from synergrasp.figures.synergy_fit import figure_explained_variance

        with _writing("--png", args.png):
            figure_explained_variance(fit, args.png)
        print(f"explained variance: {args.png}")
    return 0


def _grasp(args: argparse.Namespace) -> int:
    from synergrasp.file_output import replacing
    from synergrasp.input_checks import checked_scenario
    from synergrasp.inspector import default_sets, inspect_grasp, parse_sets

    config = _configuration(args)
    cfg, warnings = checked_scenario(config)
    for warning in warnings:
        print(f"synergrasp grasp: warning: {warning}", file=sys.stderr)
    sets, forces = None, None
    if args.sets or args.forces:
        from synergrasp.hand.kinematics import load_hand
        from synergrasp.hand.synergies import load_synergies

        n = load_synergies(cfg["synergies"], joint_names=load_hand(cfg["hand"]).joint_names).matrix.shape[1]
        sets = parse_sets(args.sets, n) if args.sets else default_sets(n)
        if args.forces:
            (forces,) = parse_sets([args.forces], n, "--forces")
            sets += [forces] if forces not in sets else []
    result = inspect_grasp(config, args.object, args.alpha, args.beta, sets, args.results)
    print(json.dumps(result.to_dict(), indent=1) if args.json else format_inspection(result))
    if args.png:
        from synergrasp.inspector import grasp_picture

        with _writing("--png", args.png):
            grasp_picture(result, args.png)
        if not args.json:
            print(f"picture: {args.png}")
    if args.html:
        from synergrasp.figures.grasp_3d import grasp_page
        from synergrasp.inspector import grasp_view

        page = grasp_page(grasp_view(result, forces))
        with _writing("--html", args.html), replacing(args.html) as partial:
            partial.write_text(page, encoding="utf-8")
        if not args.json:
            print(f"3-D page: {args.html}")
    return 0


class _WriteError(ValueError):
    """An output that could not be written after the work (one line naming the option)."""


@contextmanager
def _writing(option: str, path: str) -> Iterator[None]:
    """A failure to write ``path`` (a full disk after the check) as one line naming the option."""
    try:
        yield
    except OSError as err:
        raise _WriteError(f"{option} {path}: cannot be written ({err.strerror or err})") from None


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command; 0 on success, 2 on bad input (one line per problem on standard
    error, naming the argument, the file or the key; no traceback). The counts and every
    output path are checked before any work, for every command."""
    args = _parser().parse_args(argv)
    command = _command(args)
    lines = _count_problems(args) + _output_problems(args)
    if not lines:
        run = {
            "plan": _plan,
            "synergies fit": _fit_synergies,
            "synergies map": _map_synergies,
            "hand show": _show_hand,
            "grasp": _grasp,
        }[command]
        try:
            return run(args)
        except ValueError as err:  # grasp: ConfigError, InspectionError, file errors; every command: a write
            if args.command != "grasp" and not isinstance(err, _WriteError):
                raise
            lines = str(err).splitlines() or [repr(err)]
    print("\n".join(f"synergrasp {command}: {line}" for line in lines), file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
