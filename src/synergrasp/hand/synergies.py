"""Postural synergies of the 19-joint hand: mapping from human data, loading, validation.

A synergy file is a CSV with one row per hand joint and the columns ``joint``,
``mean_rad`` (the mean posture q_m, rad) and ``syn1`` … ``synK`` (synergy vectors, rad per
unit of the synergy coordinate σ). The shipped tables, by name (:data:`SHIPPED_TABLES`),
``data/synergies_<name>.csv``, are generated from the human synergies
(``data/santello_synergies_20dof.csv``) and the mappings ``data/synergy_mapping_<name>.yaml``
by :func:`map_human_synergies`; regenerate them with ``tools/synergy_tables.py``.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from synergrasp.hand.description import SHIPPED_HANDS, shipped_hand_path
from synergrasp.hand.kinematics import JOINT_NAMES, load_hand
from synergrasp.yaml_io import read_yaml

__all__ = [
    "Synergies",
    "SynergyFileError",
    "HUMAN_JOINT_NAMES",
    "load_synergies",
    "synergy_values",
    "load_human_synergies",
    "load_synergy_mapping",
    "map_human_synergies",
    "SynergyPath",
    "write_synergies",
    "shipped_path",
    "SHIPPED_TABLES",
    "shipped_hand_table",
    "DEFAULT_TABLE",
]

HUMAN_JOINT_NAMES: tuple[str, ...] = (
    "thumb_j1",
    "thumb_j2",
    "thumb_j3",
    "thumb_j4",
    "index_abd",
    "index_mcp",
    "index_pip",
    "index_dip",
    "middle_abd",
    "middle_mcp",
    "middle_pip",
    "middle_dip",
    "ring_abd",
    "ring_mcp",
    "ring_pip",
    "ring_dip",
    "little_abd",
    "little_mcp",
    "little_pip",
    "little_dip",
)
"""Joints of the 20-joint human hand of the human synergy data, in file order."""

SHIPPED_TABLES: tuple[str, ...] = ("softhand_opposed", "legacy_thumb", "softhand_human_higher")
"""Shipped synergy tables, by name: the same long fingers; ``softhand_opposed`` couples the
thumb to the fingers' flexion as on the real SoftHand (it opposes while the hand closes),
``legacy_thumb`` drives it by the human thumb joints, ``softhand_human_higher`` couples it in
the mean posture and S1 and drives it by the human thumb joints in S2…S15 (docs/synergies.md)."""
DEFAULT_TABLE = "softhand_opposed"
HUMAN_SYNERGIES = "santello_synergies_20dof.csv"


class SynergyFileError(ValueError):
    """A synergy file (or mapping) is malformed; the message names file, field and what is allowed."""


def read_text_table(path: str | Path, where: str) -> pd.DataFrame:
    """A CSV file's cells as text; SynergyFileError prefixed ``where`` if it cannot be read."""
    if Path(path).is_dir():
        raise SynergyFileError(f"{where}: cannot be read: is a folder; give a file")
    try:
        return pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    except OSError as err:
        raise SynergyFileError(f"{where}: cannot be read ({err.strerror or err})") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as err:
        raise SynergyFileError(f"{where}: not a readable CSV table ({err})") from None


def finite_cells(table: Any, columns: Sequence[str], problem: Callable[[int, str, str], str]) -> NDArray[np.float64]:
    """(rows, len(columns)) the table's text cells as floats (rad); a cell that is no finite
    number raises SynergyFileError with ``problem(row, column, text)`` (row 0-based)."""
    values = np.empty((len(table), len(columns)))
    for j, col in enumerate(columns):
        for i, text in enumerate(table[col].tolist()):
            try:
                value = float(text)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise SynergyFileError(problem(i, col, text))
            values[i, j] = value
    return values


@dataclass(frozen=True)
class Synergies:
    """Synergy matrix and mean posture of a hand.

    Attributes
    ----------
    joint_names : joint names, row order of ``mean`` and ``matrix``.
    mean : (n,) mean posture q_m, rad; the origin of the synergy coordinates.
    matrix : (n, k) synergy vectors as columns, rad per unit σ.
    names : ("S1", …, "Sk").
    """

    joint_names: tuple[str, ...]
    mean: NDArray[np.float64]
    matrix: NDArray[np.float64]
    names: tuple[str, ...]

    def __post_init__(self) -> None:
        mean = np.array(self.mean, dtype=float)
        matrix = np.array(self.matrix, dtype=float)
        n = len(self.joint_names)
        if mean.shape != (n,) or matrix.ndim != 2 or matrix.shape[0] != n:
            raise ValueError(
                f"Synergies: mean must be ({n},) and matrix ({n}, k) for {n} joints; got {mean.shape} and {matrix.shape}"
            )
        if len(self.names) != matrix.shape[1]:
            raise ValueError(f"Synergies: {len(self.names)} names for {matrix.shape[1]} columns")
        mean.setflags(write=False)
        matrix.setflags(write=False)
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "matrix", matrix)
        object.__setattr__(self, "joint_names", tuple(self.joint_names))
        object.__setattr__(self, "names", tuple(self.names))

    @property
    def n_synergies(self) -> int:
        return self.matrix.shape[1]

    def columns(self, indices: Sequence[int]) -> NDArray[np.float64]:
        """The (n, s) matrix of the synergies with the given 1-based indices, in that order."""
        idx = list(indices)
        bad = [i for i in idx if not (isinstance(i, (int, np.integer)) and 1 <= i <= self.n_synergies)]
        if bad:
            raise ValueError(f"synergy indices {bad} are not allowed; allowed: 1..{self.n_synergies}")
        return self.matrix[:, [i - 1 for i in idx]]


def _data_file(name: str) -> Path:
    return Path(str(resources.files("synergrasp") / "data" / name))


def _check_table_name(name: str) -> None:
    if name not in SHIPPED_TABLES:
        raise SynergyFileError(
            f"synergies: {name!r} is not a shipped table; allowed names: {list(SHIPPED_TABLES)} (or the path of a CSV file)"
        )


def shipped_path(name: str = DEFAULT_TABLE) -> Path:
    """Path of the shipped 19-joint synergy table ``name`` (one of SHIPPED_TABLES)."""
    _check_table_name(name)
    return _data_file(f"synergies_{name}.csv")


def mapping_path(name: str = DEFAULT_TABLE) -> Path:
    """Path of the human-to-hand mapping of the shipped table ``name``."""
    _check_table_name(name)
    return _data_file(f"synergy_mapping_{name}.yaml")


def resolve_synergies(source: str | Path | None) -> Path:
    """The CSV file of a ``synergies:`` value: None (the default table), the name of a shipped
    table (SHIPPED_TABLES) or a path. A value that is neither a name nor an existing file
    raises SynergyFileError naming both the allowed names and the path tried."""
    if source is None:
        return shipped_path()
    if str(source) in SHIPPED_TABLES:
        return shipped_path(str(source))
    if str(source) in SHIPPED_HANDS:  # a shipped hand's own table (its hand: the same name)
        return shipped_hand_table(str(source))
    path = Path(source)
    if path.is_dir():
        raise SynergyFileError(f"synergy file '{source}': is a folder; give a synergy CSV file or a shipped table's name")
    if not path.is_file():
        raise SynergyFileError(
            f"synergy file '{source}': is neither a shipped table {[*SHIPPED_TABLES, *SHIPPED_HANDS]} nor an existing CSV file"
        )
    return path


def _syn_names(k: int) -> list[str]:
    return [f"syn{i}" for i in range(1, k + 1)]


def _read_table(path: str | Path, joint_names: Sequence[str]) -> tuple[list[str], NDArray, NDArray]:
    """Read and validate a synergy CSV; return (syn columns, mean, matrix) in joint_names order."""
    where = f"synergy file '{path}'"
    table = read_text_table(path, where)
    columns = [str(c).strip() for c in table.columns]
    table.columns = columns
    for required in ("joint", "mean_rad"):
        if required not in columns:
            raise SynergyFileError(f"{where}: missing column '{required}'; the columns must be joint, mean_rad, syn1..synK")
    if columns[:2] != ["joint", "mean_rad"]:
        raise SynergyFileError(f"{where}: columns start {columns[:2]}; they must be joint, mean_rad, syn1..synK")
    syn_cols = columns[2:]
    if not syn_cols:
        raise SynergyFileError(f"{where}: no synergy columns; expected syn1..synK after mean_rad")
    if syn_cols != _syn_names(len(syn_cols)):
        raise SynergyFileError(
            f"{where}: synergy columns {syn_cols} are not allowed; they must be named syn1..syn{len(syn_cols)} in this order"
        )

    names = [s.strip() for s in table["joint"].tolist()]
    expected = list(joint_names)
    duplicated = sorted({n for n in names if names.count(n) > 1})
    unknown = [n for n in names if n not in expected]
    missing = [n for n in expected if n not in names]
    if duplicated or unknown or missing:
        parts = []
        if duplicated:
            parts.append(f"duplicated {duplicated}")
        if unknown:
            parts.append(f"unknown {unknown}")
        if missing:
            parts.append(f"missing {missing}")
        raise SynergyFileError(f"{where}: field 'joint': {'; '.join(parts)}; expected exactly one row for each of {expected}")
    if len(syn_cols) > len(expected):
        raise SynergyFileError(
            f"{where}: {len(syn_cols)} synergy columns for {len(expected)} joints; at most {len(expected)} are allowed"
        )

    values = finite_cells(
        table,
        ["mean_rad", *syn_cols],
        lambda i, col, text: f"{where}: field '{col}' of joint '{names[i]}' is {text!r}; a finite number (rad) is required",
    )
    order = [names.index(n) for n in expected]
    values = values[order]
    return syn_cols, values[:, 0], values[:, 1:]


def load_synergies(path: str | Path | None = None, joint_names: Sequence[str] = JOINT_NAMES) -> Synergies:
    """Load a synergy file (joint, mean_rad, syn1..synK; rad and rad per unit σ).

    ``path``: None (the default shipped table), a shipped table's name (SHIPPED_TABLES) or a
    CSV path. Rows may come in any order; the result follows ``joint_names``.

    Raises
    ------
    SynergyFileError
        Naming the file, the field and what is allowed.
    """
    path = resolve_synergies(path)
    syn_cols, mean, matrix = _read_table(path, joint_names)
    return Synergies(tuple(joint_names), mean, matrix, tuple(f"S{i}" for i in range(1, len(syn_cols) + 1)))


def synergy_values(hand: str | Path | None, synergies: str | Path | None, columns: Sequence[int]) -> dict[str, list[float]]:
    """The mean posture (``mean_rad``) and the synergies ``columns`` (1-based: ``S1``, ...) of
    the synergy table ``synergies`` loaded for the hand file ``hand`` (None: the shipped
    ones): rad, in the hand's joint order, the exact float64 values. What a step that reads
    only these is handed instead of the table (``synergrasp.steps``)."""
    return json.loads(_synergy_values(hand, synergies, tuple(int(i) for i in columns)))


@functools.cache
def _synergy_values(hand: str | Path | None, synergies: str | Path | None, columns: tuple[int, ...]) -> str:
    table = load_synergies(synergies, joint_names=load_hand(hand).joint_names)
    values = {"mean_rad": table.mean.tolist()}
    values.update({f"S{i}": table.columns([i])[:, 0].tolist() for i in columns})
    return json.dumps(values)


def load_human_synergies(path: str | Path | None = None) -> Synergies:
    """The 20-joint human synergies (Santello et al. 1998 via SynGrasp); None = the shipped copy."""
    return load_synergies(_data_file(HUMAN_SYNERGIES) if path is None else path, HUMAN_JOINT_NAMES)


def load_synergy_mapping(path: str | Path | None = None) -> dict[str, Any]:
    """A human-to-hand joint mapping (YAML, see data/synergy_mapping_<name>.yaml): None (the
    default table's), a shipped table's name or a path."""
    if path is None or str(path) in SHIPPED_TABLES:
        path = mapping_path(DEFAULT_TABLE if path is None else str(path))
    return read_yaml(path, "synergy mapping file")


def map_human_synergies(
    human_table: Synergies, mapping: Mapping[str, Any], joint_names: Sequence[str] = JOINT_NAMES
) -> Synergies:
    """Map human synergies onto the hand's joints.

    For each hand joint j (``mapping["joints"][j]``: ``terms`` [{human, weight}],
    ``offset_rad``, ``limits_deg`` [lower, upper], optionally ``column_terms``
    [{columns: [first, last], terms}]):
    q_m[j] = clip(offset + Σ weight · q_m,human, limits) and
    S[j, c] = column_sign[c] · Σ weight · S_human[·, c], with the weights of the
    ``column_terms`` entry whose 1-based column range [first, last] holds c, else ``terms``.
    Clipping the mean keeps the origin of the synergy coordinates reachable.

    Parameters
    ----------
    human_table : human synergies (rad), e.g. :func:`load_human_synergies`.
    mapping : parsed mapping, e.g. :func:`load_synergy_mapping`.
    joint_names : the hand's joints; the mapping must cover each exactly once.
    """
    joints = mapping.get("joints")
    if not isinstance(joints, Mapping):
        raise SynergyFileError("synergy mapping: field 'joints' must map each hand joint to its terms")
    unknown = [j for j in joints if j not in joint_names]
    missing = [j for j in joint_names if j not in joints]
    if unknown or missing:
        raise SynergyFileError(
            f"synergy mapping: field 'joints': unknown {unknown}, missing {missing}; expected {list(joint_names)}"
        )
    k = human_table.n_synergies
    signs = np.ones(k)
    for col, sign in (mapping.get("column_sign") or {}).items():
        if col not in _syn_names(k) or sign not in (1, -1):
            raise SynergyFileError(
                f"synergy mapping: field 'column_sign': {col}: {sign} is not allowed; keys syn1..syn{k}, values +1 or -1"
            )
        signs[int(col[3:]) - 1] = sign

    n = len(joint_names)
    weights = np.zeros((n, len(human_table.joint_names)))
    overrides = []  # (hand joint, first column, last column, weights), columns 1-based
    offsets = np.zeros(n)
    lower = np.zeros(n)
    upper = np.zeros(n)
    for j, name in enumerate(joint_names):
        spec = joints[name]
        weights[j] = _term_weights(spec["terms"], name, human_table.joint_names)
        for entry in spec.get("column_terms") or ():
            overrides.append((j, *_column_range(entry, name, k), _term_weights(entry["terms"], name, human_table.joint_names)))
        offsets[j] = float(spec.get("offset_rad", 0.0))
        lower[j], upper[j] = np.radians(spec["limits_deg"])
        if not lower[j] < upper[j]:
            raise SynergyFileError(
                f"synergy mapping: joint '{name}': limits_deg {spec['limits_deg']} must be [lower, upper] with lower < upper"
            )
    mean = np.clip(offsets + weights @ human_table.mean, lower, upper)
    combined = weights @ human_table.matrix
    for j, first, last, row in overrides:
        combined[j, first - 1 : last] = row @ human_table.matrix[:, first - 1 : last]
    matrix = combined * signs + 0.0  # + 0.0 turns -0.0 into 0.0
    return Synergies(tuple(joint_names), mean, matrix, human_table.names)


def _term_weights(terms: Sequence[Mapping[str, Any]], joint: str, human_names: Sequence[str]) -> NDArray[np.float64]:
    """The weights on the human joints of one hand joint's ``terms`` [{human, weight}]."""
    out = np.zeros(len(human_names))
    for term in terms:
        if term["human"] not in human_names:
            raise SynergyFileError(
                f"synergy mapping: joint '{joint}': human joint {term['human']!r} is not allowed; allowed: {list(human_names)}"
            )
        out[list(human_names).index(term["human"])] += float(term["weight"])
    return out


def _column_range(entry: Mapping[str, Any], joint: str, k: int) -> tuple[int, int]:
    """The 1-based inclusive column range [first, last] of a ``column_terms`` entry."""
    cols = entry.get("columns")
    if (
        not isinstance(cols, Sequence)
        or len(cols) != 2
        or not all(isinstance(c, int) for c in cols)
        or not 1 <= cols[0] <= cols[1] <= k
    ):
        raise SynergyFileError(
            f"synergy mapping: joint '{joint}': field 'column_terms.columns' is {cols!r}; "
            f"allowed: [first, last], whole numbers with 1 <= first <= last <= {k}"
        )
    return cols[0], cols[1]


@dataclass(frozen=True)
class SynergyPath:
    """The joint reference along one synergy: q_r(σ) = clip(q_m + σ·S_k, lower, upper), rad.

    mean (n,) q_m, rad; direction (n,) S_k, rad per unit σ; lower, upper (n,) joint limits, rad.
    The closure follows it along S1 (:meth:`along`); Fig. 1 along S1…S7.
    """

    mean: NDArray[np.float64]
    direction: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]

    @classmethod
    def along(cls, synergies: Synergies, lower: ArrayLike, upper: ArrayLike, synergy: int = 1) -> SynergyPath:
        """The path along synergy ``synergy`` (1-based) within the limits ``lower``, ``upper`` (rad)."""
        n = len(synergies.joint_names)
        lower_arr = np.asarray(lower, dtype=float)
        upper_arr = np.asarray(upper, dtype=float)
        if lower_arr.shape != (n,) or upper_arr.shape != (n,):
            raise ValueError(f"lower and upper must have shape ({n},); got {lower_arr.shape} and {upper_arr.shape}")
        direction = synergies.columns([synergy])[:, 0]
        return cls(synergies.mean, direction, lower_arr, upper_arr)

    def reference(self, sigma: ArrayLike) -> NDArray[np.float64]:
        """q_r(σ), rad: (n,) for a scalar σ, (m, n) for (m,) values of σ."""
        sigma_arr = np.asarray(sigma, dtype=float)
        if sigma_arr.ndim > 1:
            raise ValueError(f"sigma must be a scalar or 1-D; got shape {sigma_arr.shape}")
        return np.clip(self.mean + sigma_arr[..., None] * self.direction, self.lower, self.upper)

    def closure_range(self, flexion: ArrayLike) -> tuple[float, float]:
        """(σ_open, σ_closed) of a closure along this path.

        σ_open: the fully open hand, the largest σ at which every flexion joint (``flexion``,
        (n,) bool) with a non-zero entry is at its lower limit. σ_closed: the end of the
        path, the σ from which on every joint with a non-zero entry is clipped at a limit.
        Raises ValueError if a flexion entry is negative: the synergy must close the hand.
        """
        flex = np.asarray(flexion, dtype=bool)
        moving = self.direction != 0
        if np.any(self.direction[flex] < 0):
            raise ValueError(
                "the closing synergy S1 must have flexion entries >= 0 (increasing σ closes "
                f"the hand); negative at joint indices {np.flatnonzero(flex & (self.direction < 0)).tolist()}"
            )
        if not np.any(flex & moving):
            raise ValueError("the closing synergy S1 moves no flexion joint")
        lo, hi = self.active_interval()
        return float(np.min(lo[flex & moving])), float(np.max(hi[moving]))

    def active_interval(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Per joint, the σ interval [lo, hi] on which its reference is inside its limits
        (outside it the joint is clipped and does not move); (inf, −inf) where S_k is 0."""
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (self.lower - self.mean) / self.direction
            b = (self.upper - self.mean) / self.direction
        moving = self.direction != 0
        return np.where(moving, np.minimum(a, b), np.inf), np.where(moving, np.maximum(a, b), -np.inf)


def write_synergies(synergies: Synergies, path: str | Path) -> None:
    """Write a synergy file (joint, mean_rad, syn1..synK) that round-trips exactly."""
    table = pd.DataFrame(synergies.matrix, columns=_syn_names(synergies.n_synergies))
    table.insert(0, "mean_rad", synergies.mean)
    table.insert(0, "joint", list(synergies.joint_names))
    table.to_csv(path, index=False, float_format="%.17g", lineterminator="\n")


def shipped_hand_table(name: str) -> Path:
    """The synergy table of the shipped hand ``name`` (one of SHIPPED_HANDS), beside its
    description: ``synergies.csv``."""
    return shipped_hand_path(name).parent / "synergies.csv"


def shadow_hand_files() -> tuple[Path, Path, Path]:
    """(hand description, human-to-hand mapping, synergy table) of the shipped Shadow hand."""
    folder = _data_file("hands") / "shadow"
    return folder / "hand.yaml", folder / "synergy_mapping_human.yaml", folder / "synergies.csv"
