"""The ``synergrasp`` console command (docs/inspector.md).

    synergrasp grasp obj4 --alpha -30 --beta 0 [--configfile my.yaml] [--sets 1 1-5 1-15] [--json]
                     [--png grasp.png] [--html grasp.html [--forces 1-15]]
    synergrasp synergies fit POSTURES.csv --out synergies.csv [--synergies K] [--png variance.png]
    synergrasp hand show [HAND] [--synergies TABLE] [--png hand.png] [--count K]

Bad input (an argument, a configuration file, the hand or synergy file it names, an output
path that cannot be written) ends with one line per problem naming the argument, the file or
the key, and exit status 2, before any work: the configuration goes through the workflow's
own checks (``synergrasp.study_checks``). Warnings on the configuration are printed too.

    synergrasp plan obj4 [--radius 10 20 30] [--configfile my.yaml] [--results results] [--csv plan.csv]
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
_OPPOSITION_WORDS = {"palm": "held against the palm: a power grasp", "pad": "between the thumb's and the fingers' pads: "
                     "a precision grip", "side": "thumb pad against the side of the index: a lateral pinch",
                     "none": "no two contact groups push against each other"}

#: The optimisation's status under the object's weight, in words.
_WEIGHT_WORDS = {"feasible": "feasible", "infeasible": "infeasible", "rank_deficient": "rank(G) < 6",
                 "no_grasp": "no grasp", "numerical_failure": "solver failed"}


def format_inspection(result: Any) -> str:
    """The inspection as text: pose, contacts, quality indices, one line per synergy set."""
    from synergrasp.ids import set_name

    lines = [f"{result.object} at alpha = {result.alpha_deg:g} deg, beta = {result.beta_deg:g} deg (pose {result.pose}): "
             f"{result.closure_status}, {len(result.contacts)} contacts; weight {result.weight_N:.3g} N; "
             f"opposition: {result.opposition} ({_OPPOSITION_WORDS[result.opposition]})"]
    if len(result.contacts):
        lines.append(f"  {'link':<14} {'point (mm)':<28} {'inward normal':<23} face        on")
        for row in result.contacts.itertuples():
            point = ", ".join(f"{v:7.2f}" for v in row.point_mm)
            normal = ", ".join(f"{v:6.3f}" for v in row.normal)
            lines.append(f"  {row.link_name:<14} ({point})  ({normal})  {row.face:<11} {row.feature}")
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
        lines += _blocker_lines(result.sets)
    return "\n".join(lines)


#: Why a set fails when no contact is named (docs/blockers.md).
_REASON_WORDS = {"no_internal_force": "no internal force (e_s = 0)", "rank_deficient": "rank(G) < 6",
                 "no_squeeze": "every internal force it reaches has zero total normal force",
                 "numerical_failure": "the max-margin problem was not solved"}


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
            lines.append(f"    contact {b.contact}: {b.link_name} ({b.link_kind}), {b.face} on {article} {b.feature}, "
                         f"normal force {b.normal_force:+.3g}, {_number(b.angle_outside_deg)} deg outside its cone")
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
    grasp.add_argument("--sets", nargs="+", help="synergy sets: k, a-b (S_a..S_b) or a,b,c (default: each "
                                                 "single synergy and {S1..Sk} for every k)")
    grasp.add_argument("--results", default=RESULTS, help="where the study's outputs are (the searched "
                                                            "placement's target: <results>/objects/<object>/placement.csv)")
    grasp.add_argument("--json", action="store_true", help="print the result as JSON")
    grasp.add_argument("--png", metavar="PATH", help="write the grasp drawn as in Fig. 2 from two views (PNG)")
    grasp.add_argument("--html", metavar="PATH", help="write the grasp in 3-D, with the optimal contact forces of "
                                                      "one set as arrows, as one self-contained page")
    grasp.add_argument("--forces", metavar="SET", help="the set whose forces --html draws (default: the last set "
                                                       "asked, {S1..Sk} of every synergy by default)")
    synergies = sub.add_parser("synergies", help="synergy tables").add_subparsers(dest="action", required=True)
    fit = synergies.add_parser("fit", help="fit a synergy table to postures (principal components, docs/synergies.md)")
    fit.add_argument("postures", help="CSV: one column per joint, one row per posture, rad")
    fit.add_argument("--out", required=True, help="the synergy table to write (joint, mean_rad, syn1..synK)")
    fit.add_argument("--synergies", type=int, help="how many synergies to keep (default: all with variance)")
    fit.add_argument("--png", metavar="PATH", help="write the explained variance per synergy (PNG)")
    hands = sub.add_parser("hand", help="hands").add_subparsers(dest="action", required=True)
    show = hands.add_parser("show", help="print a hand's joints; draw it at its mean posture and along each synergy")
    show.add_argument("hand", nargs="?", help="a hand file or description, or shadow_hand (default: the shipped hand)")
    show.add_argument("--synergies", help="a synergy table (name or CSV; default: the shipped one, or shadow_hand's)")
    show.add_argument("--png", metavar="PATH", help="write the hand at q_m + sigma S_k, sigma = -1, 0, +1 (PNG)")
    show.add_argument("--count", type=int, default=7, help="synergies drawn (default 7)")
    plan = sub.add_parser("plan", help="the incremental planner on one object, against the study's exhaustive search "
                                       "(reads <results>/objects/<object>/contacts and gfo tables; docs/planner.md)")
    plan.add_argument("object", help="an object of the configuration")
    plan.add_argument("--radius", type=float, nargs="+", help="neighbourhood radii, deg (default: "
                                                              "analyses.planner_radii_deg)")
    plan.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    plan.add_argument("--results", default=RESULTS, help="where the study's outputs are")
    plan.add_argument("--csv", metavar="PATH", help="write the plan table (one row per radius) as CSV")
    return parser


def _output_problems(args: argparse.Namespace) -> list[str]:
    """What keeps ``--png`` / ``--html`` from being written, one line each, before any work."""
    problems = []
    for option, path, suffixes in (("--png", args.png, (".png",)), ("--html", args.html, (".html", ".htm"))):
        if path is None:
            continue
        target = Path(path)
        folder = target.parent
        if target.suffix.lower() not in suffixes:
            problems.append(f"{option} {path}: the file name must end in {' or '.join(suffixes)}")
        elif target.is_dir():
            problems.append(f"{option} {path}: is a folder; give a file name")
        elif not folder.is_dir():
            problems.append(f"{option} {path}: folder '{folder}' is not an existing folder")
        else:
            try:  # a file written and removed in that folder: permissions, a read-only disk
                with tempfile.NamedTemporaryFile(dir=folder, prefix=f".{target.name}."):
                    pass
            except OSError as err:
                problems.append(f"{option} {path}: folder '{folder}' cannot be written ({err.strerror or err})")
    return problems


def _plan(args: argparse.Namespace) -> int:
    """``synergrasp plan``: the planner at each radius, one line each."""
    from dataclasses import replace

    from synergrasp import tables
    from synergrasp.analysis.plan_study import PlanParams, plan_object
    from synergrasp.config import ConfigError
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.steps import object_file
    from synergrasp.study_checks import checked_scenario, read_overlays

    try:
        cfg, _ = checked_scenario(read_overlays(args.configfile))
        if args.object not in cfg["objects"]:
            raise ConfigError(f"object {args.object!r} is not in the configuration ({', '.join(cfg['objects'])})")
        params = PlanParams.from_config(cfg, args.object)
        params = replace(params, radii_deg=tuple(args.radius)) if args.radius else params
        # the files the workflow's rules read for this configuration, not whichever exists
        contacts = tables.read(tables.CONTACTS, object_file(cfg, "contacts", args.object, args.results))
        gfo = tables.read(tables.GFO, object_file(cfg, "optimise", args.object, args.results))
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


def _show_hand(args: argparse.Namespace) -> int:
    """``synergrasp hand show``: the joints (limits, mean posture, S1), links and fingertips."""
    from synergrasp.hand.kinematics import fingertip_positions, load_hand
    from synergrasp.hand.synergies import load_synergies

    try:
        hand = load_hand(args.hand)
        table = args.synergies or ("shadow_hand" if args.hand == "shadow_hand" else None)
        synergies = load_synergies(table, joint_names=hand.joint_names)
    except ValueError as err:
        print(f"synergrasp hand show: {err}", file=sys.stderr)
        return 2
    deg = math.degrees
    print(f"{hand.name} ({hand.source}): {hand.n_joints} joints, {hand.n_links} links "
          f"({len(hand.shapeless_links)} without shape), {synergies.n_synergies} synergies")
    print(f"{'joint':<15} {'lower':>7} {'upper':>7} {'mean':>7} {'S1':>8}   (deg; S1 rad per unit sigma)")
    for j, name in enumerate(hand.joint_names):
        print(f"{name:<15} {deg(hand.lower[j]):7.1f} {deg(hand.upper[j]):7.1f} {deg(synergies.mean[j]):7.1f} "
              f"{synergies.matrix[j, 0]:8.3f}")
    tips = fingertip_positions(hand, synergies.mean)
    print("fingertips at the mean posture (palm frame, mm): " + "; ".join(
        f"{hand.link_finger[link]} ({', '.join(f'{v:.1f}' for v in tip)})" for link, tip in zip(hand.fingertip_link, tips)))
    if args.png:
        from synergrasp.figures.hand_figures import figure_synergy_postures

        figure_synergy_postures(hand, synergies, args.png, None, n_synergies=min(args.count, synergies.n_synergies))
        print(f"picture: {args.png}")
    return 0


def _fit_synergies(args: argparse.Namespace) -> int:
    """``synergrasp synergies fit``: the table, and the variance explained printed (and drawn)."""
    from synergrasp.hand.synergies import SynergyFileError, write_synergies
    from synergrasp.hand.synergy_fit import fit_synergies, read_postures

    try:
        names, postures = read_postures(args.postures)
        fit = fit_synergies(names, postures, args.synergies)
    except (SynergyFileError, ValueError) as err:
        print(f"synergrasp synergies fit: {err}", file=sys.stderr)
        return 2
    write_synergies(fit.synergies, args.out)
    print(f"{len(postures)} postures of {len(names)} joints: total variance {fit.total_variance_rad2:.6g} rad^2")
    print(f"{'synergy':<8} {'variance (rad^2)':>17} {'explained':>10} {'cumulative':>11}")
    for i, (v, e, c) in enumerate(zip(fit.variance_rad2, fit.explained, fit.cumulative), start=1):
        print(f"S{i:<7} {v:>17.6g} {100 * e:>9.2f}% {100 * c:>10.2f}%")
    print(f"synergy table: {args.out}")
    if args.png:
        from synergrasp.figures.synergy_fit import figure_explained_variance

        figure_explained_variance(fit, args.png)
        print(f"explained variance: {args.png}")
    return 0




def _grasp(args: argparse.Namespace) -> int:
    from synergrasp.file_output import replacing
    from synergrasp.inspector import default_sets, inspect_grasp, parse_sets
    from synergrasp.study_checks import checked_scenario, read_overlays

    problems = _output_problems(args)
    if problems:
        raise ValueError("\n".join(problems))
    config = read_overlays(args.configfile)
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


@contextmanager
def _writing(option: str, path: str) -> Iterator[None]:
    """A failure to write ``path`` (a full disk after the check) as one line naming the option."""
    try:
        yield
    except OSError as err:
        raise ValueError(f"{option} {path}: cannot be written ({err.strerror or err})") from None


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command; 0 on success, 2 on bad input (one line per problem on standard
    error, naming the argument, the file or the key; no traceback)."""
    args = _parser().parse_args(argv)
    if args.command == "plan":
        return _plan(args)
    if args.command == "synergies":
        return _fit_synergies(args)
    if args.command == "hand":
        return _show_hand(args)
    try:
        return _grasp(args)
    except ValueError as err:  # ConfigError, InspectionError, file errors: each names what is wrong
        lines = str(err).splitlines() or [repr(err)]
    print("\n".join(f"synergrasp {args.command}: {line}" for line in lines), file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
