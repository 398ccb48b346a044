"""A grasp in 3-D in the browser (docs/inspector.md): the hand's bodies, the object, the
contact points and the optimal contact forces of one synergy set as arrows, on one page a
reader can turn and zoom (plotly: WebGL, no server).

The hand is what the closure collides (``synergrasp.figures.hand_pictures.hand_shapes``): a
capsule per phalanx, drawn as a triangle mesh, and the palm's boxes; the object is its
shape's own surface mesh (``Shape.surface_mesh``: any shape of
``synergrasp.simulation.shapes``). The links touching the object have their own colours and
are the legend's entries; an arrow starts at its contact point and shows the force the hand
applies to the object there, its length to the scale the legend's title states. Positions
in the palm frame, mm; forces in N.

The pages of the Fig. 2 grasps (``write_grasp_pages``) load one copy of plotly's script,
``plotly.min.js``, from beside them; a page written alone holds it (``grasp_page``).
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from synergrasp.figures.hand_pictures import ABOVE_CAMERA, BOX, PALM_CAMERA, SKIN, ShapeInPicture, hand_shapes
from synergrasp.file_output import replacing_folder
from synergrasp.ids import set_name
from synergrasp.optimisation.optimise import GFOParams
from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.opposition import HandAxes, OppositionRule, contacts_oppositions
from synergrasp.simulation.shapes.surface import Surface, frame_along, merge_meshes, placed, revolution_mesh

__all__ = [
    "GraspScene",
    "Grasps3dParams",
    "grasp_figure",
    "grasp_page",
    "write_grasp_pages",
    "fig2_scenes",
    "arrow_scale",
    "PLOTLY_JS",
    "ZERO_FORCE_N",
    "ARROW_REACH",
]

#: The file name of plotly's script beside the pages that share it.
PLOTLY_JS = "plotly.min.js"
#: Forces no larger than this (N) get no arrow.
ZERO_FORCE_N = 1e-6
#: The longest arrow is at most this share of the object's bounding radius.
ARROW_REACH = 1.5
#: Colours of the touching links, in the order they are listed (none near the object's blue or the skin).
LINK_COLOURS = ("#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f", "#1a1a1a")
_CAPSULE_SEGMENTS = 16
_HEAD_MM = 7.0  # arrow head length


def _rgb(colour: Sequence[float]) -> str:
    return "rgb({}, {}, {})".format(*(int(round(255 * c)) for c in colour))


@dataclass(frozen=True)
class GraspScene:
    """One grasp to show: the hand (``synergrasp.hand.kinematics.Hand``) at joint angles ``q``
    (rad); the object (shape and pose); per contact its hand link, point (m, 3) mm and the
    optimal force on the object (m, 3) N of the synergy set named ``force_set`` (None: no
    forces, e.g. not load-feasible); a ``title``."""

    hand: Any
    q: NDArray
    shape: ShapeInPicture
    links: NDArray
    points_mm: NDArray
    forces_N: NDArray | None
    force_set: str
    title: str

    @classmethod
    def of(
        cls,
        hand: Any,
        q: ArrayLike,
        shape: ShapeInPicture,
        links: ArrayLike,
        points_mm: ArrayLike,
        forces_N: ArrayLike | None,
        force_set: str,
        title: str,
    ) -> GraspScene:
        m = len(np.ravel(links))
        return cls(
            hand,
            np.asarray(q, dtype=float),
            shape,
            np.asarray(links, dtype=np.int64).ravel(),
            np.asarray(points_mm, dtype=float).reshape(m, 3),
            None if forces_N is None or len(np.ravel(forces_N)) == 0 else np.asarray(forces_N, dtype=float).reshape(m, 3),
            force_set,
            title,
        )


def _capsule_mesh(a: NDArray, b: NDArray, r: float) -> Surface:
    """A capsule (segment a–b, radius r, mm) as a mesh: two half spheres and a cylinder."""
    length = float(np.linalg.norm(b - a))
    polar = np.linspace(0.0, 0.5 * np.pi, 5)
    profile = [(r * math.sin(t) if k else 0.0, -r * math.cos(t)) for k, t in enumerate(polar)]
    profile += [(r * math.cos(t), length + r * math.sin(t)) if k < 4 else (0.0, length + r) for k, t in enumerate(polar)]
    axis = b - a if length > 1e-9 else np.array([0.0, 0.0, 1.0])
    return placed(revolution_mesh(profile, _CAPSULE_SEGMENTS), frame_along(axis), a)


def _link_meshes(hand: Any, q: NDArray) -> dict[int, Surface]:
    """Each hand link's bodies as one mesh: its capsules, and for the palm its boxes."""
    shapes = hand_shapes(hand, q)
    parts: dict[int, list[Surface]] = {}
    for box in shapes.boxes:
        parts.setdefault(0, []).append(box.shape.surface_mesh(np.asarray(box.rotation), np.asarray(box.center_mm)))
    for (a, b), r, link in zip(shapes.ends, shapes.radius, shapes.link):
        parts.setdefault(int(link), []).append(_capsule_mesh(a, b, float(r)))
    return {link: merge_meshes(meshes) for link, meshes in parts.items()}


def _mesh_trace(mesh: Surface, colour: str, name: str, opacity: float = 1.0, **extra: Any) -> dict[str, Any]:
    (x, y, z), (i, j, k) = mesh[0].T, mesh[1].T
    return dict(
        type="mesh3d",
        x=x,
        y=y,
        z=z,
        i=i,
        j=j,
        k=k,
        color=colour,
        opacity=opacity,
        name=name,
        hovertemplate=f"{html.escape(name)}<extra></extra>",
        lighting=dict(ambient=0.55, diffuse=0.7, specular=0.15, roughness=0.6),
        **extra,
    )


def arrow_scale(forces_N: NDArray, reach_mm: float) -> float:
    """mm per N of the arrows: a 1-2-5 step, the largest force about ``reach_mm`` long at most."""
    largest = float(np.max(np.linalg.norm(forces_N, axis=1))) if len(forces_N) else 0.0
    if largest <= ZERO_FORCE_N:
        return 1.0
    raw = reach_mm / largest
    step = 10.0 ** math.floor(math.log10(raw))
    return max(m * step for m in (1.0, 2.0, 5.0) if m * step <= raw)


def _arrow_traces(points: NDArray, forces: NDArray, scale: float, colour: str, group: str, name: str) -> list[dict[str, Any]]:
    """Shafts and heads (cones) of the forces at ``points``, ``scale`` mm per N; none for a zero force."""
    norms = np.linalg.norm(forces, axis=1)
    keep = norms > ZERO_FORCE_N
    if not keep.any():
        return []
    p, f, n = points[keep], forces[keep], norms[keep]
    unit = f / n[:, None]
    tip = p + f * scale
    base = tip - unit * np.minimum(_HEAD_MM, 0.5 * n * scale)[:, None]  # a short arrow is half head
    shafts: list[Any] = []  # segments apart: a gap (None) after each
    for a, b in zip(p.tolist(), base.tolist()):
        shafts += [a, b, [None, None, None]]
    sx, sy, sz = (list(c) for c in zip(*shafts))
    text = [f"{name}: |f| = {v:.3g} N<br>f = ({a:.3g}, {b:.3g}, {c:.3g}) N" for v, (a, b, c) in zip(n, f)]
    head = unit * np.minimum(_HEAD_MM, 0.5 * n * scale)[:, None]
    return [
        dict(
            type="scatter3d",
            x=sx,
            y=sy,
            z=sz,
            mode="lines",
            line=dict(color=colour, width=8),
            legendgroup=group,
            showlegend=False,
            hoverinfo="skip",
            name=f"{name} force",
        ),
        dict(
            type="cone",
            x=tip[:, 0],
            y=tip[:, 1],
            z=tip[:, 2],
            u=head[:, 0],
            v=head[:, 1],
            w=head[:, 2],
            anchor="tip",
            sizemode="raw",
            sizeref=1.0,
            colorscale=[[0, colour], [1, colour]],
            showscale=False,
            legendgroup=group,
            showlegend=False,
            name=f"{name} force",
            text=text,
            hovertemplate="%{text}<extra></extra>",
        ),
    ]


def grasp_figure(scene: GraspScene) -> dict[str, Any]:
    """The grasp as a plotly figure, as its dict (``data``, ``layout``; plotly's own object:
    ``plotly.graph_objects.Figure(it)``): the hand's links, the object see-through, the
    contact points and force arrows; the legend lists the links touching the object (a click
    hides one with its contacts and arrows). A dict, as plotly's objects check every value
    as they are built, which takes longer than all the rest."""
    hand, meshes = scene.hand, _link_meshes(scene.hand, scene.q)
    touching = sorted(set(scene.links.tolist()))
    colours = {link: LINK_COLOURS[k % len(LINK_COLOURS)] for k, link in enumerate(touching)}
    obj = scene.shape
    traces = [
        _mesh_trace(
            obj.shape.surface_mesh(np.asarray(obj.rotation), np.asarray(obj.center_mm)),
            _rgb(BOX),
            f"object ({_shape_words(obj.shape)})",
            opacity=0.22,
            showlegend=False,
        )
    ]
    rest = [meshes[k] for k in sorted(meshes) if k not in colours]
    if rest:
        traces.append(_mesh_trace(merge_meshes(rest), _rgb(SKIN), "hand", showlegend=False))
    forces = scene.forces_N
    scale = arrow_scale(forces, ARROW_REACH * obj.shape.bounding_radius_mm) if forces is not None else 1.0
    for link in touching:
        name, group, at = hand.link_names[link], f"link {link}", scene.links == link
        if forces is not None:
            load = f", {np.linalg.norm(forces[at], axis=1).sum():.3g} N"
        else:
            load = ""
        label = f"{name.replace('_', ' ')}: {int(at.sum())} contact{'s' if at.sum() > 1 else ''}{load}"
        if link in meshes:
            traces.append(_mesh_trace(meshes[link], colours[link], label, legendgroup=group, showlegend=True))
        p = scene.points_mm[at]
        traces.append(
            dict(
                type="scatter3d",
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="markers",
                legendgroup=group,
                showlegend=False,
                name=f"{name} contact",
                marker=dict(size=5, color="white", line=dict(color=colours[link], width=3)),
                hovertemplate=f"{name} contact<br>(%{{x:.1f}}, %{{y:.1f}}, %{{z:.1f}}) mm<extra></extra>",
            )
        )
        if forces is not None:
            traces += _arrow_traces(p, forces[at], scale, colours[link], group, name)
    arrows = (
        f"arrows: optimal contact forces of {scene.force_set} on the object, 1 N = {scale:g} mm"
        if forces is not None
        else f"no arrows: {scene.force_set} is not feasible under the weight"
        if scene.force_set
        else "no arrows: no set optimised (no grasp)"
    )
    views = {
        name: _plotly_camera(camera) for name, camera in (("palm side", PALM_CAMERA), ("from above the fingertips", ABOVE_CAMERA))
    }
    axis = dict(
        showbackground=True,
        backgroundcolor="rgb(235, 238, 243)",
        gridcolor="white",
        zerolinecolor="white",
        linecolor="white",
        showspikes=False,
    )
    layout = dict(
        title=dict(
            text=f"{html.escape(scene.title)}<br><sup>palm frame, mm; hand skin-coloured, object blue "
            f"and see-through; drag to turn, scroll to zoom</sup>",
            x=0.01,
            font=dict(size=15),
        ),
        legend=dict(
            title=dict(text=f"links touching the object<br><sup>{html.escape(arrows)}</sup>"),
            bgcolor="rgba(255, 255, 255, 0.8)",
            font=dict(size=13),
        ),
        updatemenus=[
            dict(
                type="buttons",
                direction="left",
                x=0.01,
                y=0.01,
                xanchor="left",
                yanchor="bottom",
                buttons=[dict(label=name, method="relayout", args=[{"scene.camera": camera}]) for name, camera in views.items()],
            )
        ],
        scene=dict(
            aspectmode="data",
            camera=views["palm side"],
            xaxis=dict(title=dict(text="x: palm normal (mm)"), **axis),
            yaxis=dict(title=dict(text="y (mm)"), **axis),
            zaxis=dict(title=dict(text="z: along the fingers (mm)"), **axis),
        ),
        margin=dict(l=0, r=0, t=70, b=0),
        paper_bgcolor="white",
    )
    return {"data": traces, "layout": layout}


def _plotly_camera(camera: Any) -> dict[str, Any]:
    """A picture's camera (``hand_pictures.Camera``) as plotly's scene camera: looking along
    its direction at the scene's centre, its up toward the top."""
    eye = -np.asarray(camera.direction, dtype=float) / np.linalg.norm(camera.direction) * 2.3
    up = np.asarray(camera.up, dtype=float)
    return dict(
        eye=dict(x=float(eye[0]), y=float(eye[1]), z=float(eye[2])), up=dict(x=float(up[0]), y=float(up[1]), z=float(up[2]))
    )


def _shape_words(shape: Any) -> str:
    return shape.label if shape.kind in shape.label else f"{shape.kind} {shape.label}"


def grasp_page(fig: Any, plotly_js: str | None = None) -> str:
    """The figure (``grasp_figure``'s dict or a plotly Figure) as one HTML page: plotly's
    script inside it (``plotly_js`` None: a page that stands alone) or loaded from the relative
    path ``plotly_js``. Nothing is fetched from the network; the same figure gives the same page."""
    import plotly.io as pio

    return pio.to_html(
        fig,
        full_html=True,
        include_plotlyjs=True if plotly_js is None else plotly_js,
        include_mathjax=False,
        div_id="grasp",
        default_width="100%",
        default_height="100vh",
        config={"displaylogo": False, "responsive": True},
        validate=False,
    )


def write_grasp_pages(folder: str | Path, pages: Mapping[str, tuple[str, GraspScene]], title: str) -> None:
    """The pages of several grasps in ``folder``: ``<name>.html`` per entry of ``pages``
    (name -> (link text, scene)), one copy of plotly's script (``plotly.min.js``) that they
    all load, and ``index.html`` listing them beside a frame that shows the one chosen."""
    from plotly.offline import get_plotlyjs

    with replacing_folder(folder) as out:
        (out / PLOTLY_JS).write_text(get_plotlyjs(), encoding="utf-8")
        items = []
        for name, (text, scene) in pages.items():
            (out / f"{name}.html").write_text(grasp_page(grasp_figure(scene), PLOTLY_JS), encoding="utf-8")
            items.append(f'<li><a href="{name}.html" target="view">{html.escape(text)}</a></li>')
        first = f"{next(iter(pages))}.html" if pages else "about:blank"
        (out / "index.html").write_text(
            _INDEX.format(title=html.escape(title), items="\n".join(items), first=first), encoding="utf-8"
        )


@dataclass(frozen=True)
class Grasps3dParams:
    """Fig. 2 and its grasps' 3-D pages (the ``fig2`` step): the hand and synergy files
    (None: the shipped ones), the set {S1..Sk} whose optimal forces the pages draw, and every
    object with the GFO parameters of its weight."""

    hand: str | None
    synergies: str | None
    full_set: tuple[int, ...]
    objects: tuple[GraspedObject, ...]
    gfo: tuple[GFOParams, ...]
    opposition: OppositionRule

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> Grasps3dParams:
        names = list(config["objects"])
        return cls(
            config["hand"],
            config["synergies"],
            tuple(range(1, int(config["synergy_sets"]["incremental_max"]) + 1)),
            tuple(GraspedObject.from_config(config, n, with_mass=False) for n in names),
            tuple(GFOParams.from_config(config, n) for n in names),
            OppositionRule.from_config(config),
        )

    def oppositions(self, hand: Any, tables: Sequence[Any]) -> list[dict[int, str]]:
        """Per object (``tables[i]``: the contacts table of ``objects[i]``), its grasps'
        opposition by pose (docs/opposition.md)."""
        axes = HandAxes.from_hand(hand)
        return [dict(zip(t["pose"].astype(int), contacts_oppositions(t, axes, self.opposition))) for t in tables]


def fig2_scenes(
    hand: Any, synergy_matrix: NDArray, params: Grasps3dParams, tables: Sequence[Any]
) -> dict[str, tuple[str, GraspScene]]:
    """The grasps of Fig. 2 (``draw_grasp_row``'s choice, per object) with the optimal contact
    forces of ``params.full_set`` under each object's weight, by page name ``<object>_<column>``
    -> (link text, scene). ``tables[i]``: the contacts table of ``params.objects[i]``."""
    import pandas as pd

    from synergrasp.analysis.realism import representative_grasps
    from synergrasp.figures.fig1_fig2_postures_grasps import FIG2_GRASPS, object_of
    from synergrasp.optimisation.mechanics import read_grasps
    from synergrasp.optimisation.optimise import optimise_grasps
    from synergrasp.optimisation.problem import SynergySets

    sets = SynergySets(np.asarray(synergy_matrix, dtype=float), (params.full_set,))
    name_of_set = set_name(params.full_set)
    scenes = {}
    for obj, gfo, table in zip(params.objects, params.gfo, tables):
        chosen = representative_grasps(table, FIG2_GRASPS)
        rows = pd.DataFrame([table[table["pose"] == pose].iloc[0] for pose in chosen["pose"]])
        if rows.empty:
            continue
        forces = optimise_grasps(read_grasps(rows), sets, gfo, strict=False, forces=True)["forces"]
        for c, (pick, row, f) in enumerate(zip(chosen.itertuples(), rows.itertuples(), forces)):
            text = f"{obj.name}: {pick.reason}, α = {pick.alpha_deg:g}°, β = {pick.beta_deg:g}°"
            title = (
                f"{obj.name} ({_shape_words(obj.shape)}), Fig. 2 column {c + 1}: {pick.reason} "
                f"({pick.share_pct:.0f} % of grasps) at α = {pick.alpha_deg:g}°, β = {pick.beta_deg:g}°, "
                f"{int(row.n_contacts)} contacts"
            )
            scenes[f"{obj.name}_{c + 1}"] = (
                text,
                GraspScene.of(
                    hand,
                    row.q,
                    object_of(pd.Series(row._asdict()), obj.shape),
                    row.contact_link,
                    row.contact_point,
                    f,
                    name_of_set,
                    title,
                ),
            )
    return scenes


_INDEX = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>body {{margin: 0; font-family: sans-serif; display: flex; height: 100vh}}
nav {{width: 17em; padding: 0.6em; overflow-y: auto; font-size: 14px}} nav li {{margin: 0.4em 0}}
iframe {{flex: 1; border: none; border-left: 1px solid #ccc}}</style></head>
<body><nav><b>{title}</b><ul>
{items}
</ul><p>Each page opens alone too; they share plotly.min.js beside them.</p></nav>
<iframe name="view" src="{first}"></iframe></body></html>
"""
