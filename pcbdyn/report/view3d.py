"""The data of an interactive, animated 3-D mode view on an HTML page (:meth:`.html.Page.view3d`).

The page draws it with plotly.js (the bundle that the ``plotly`` wheel ships, inlined once per page:
the page stays one file that needs no network) and ``templates/view3d.js``: each scene's surface
moves as u(t) = a u_k cos(2 pi t / T), coloured by the outward normal displacement with its sign,
with its beams (ribs, stiffeners), outlines (parts, fixtures, plates, added masses) and test points
moving with it; the reader picks the mode, scales the amplitude, rotates and zooms. Scenes side by
side share the phase (test and model of a pair move together).

A scene is plain data built here from a model and its mode shapes: node coordinates [mm] as
float32, triangles as uint32, displacements per mode as int16 scaled to the mode's largest |u|,
colours as int8, all base64. A mesh whose data would pass ``max_bytes`` is coarsened by vertex
clustering (nodes snapped to a grid, each cluster one vertex carrying its nodes' mean motion), so a
page stays small whatever the model. Formatting only."""

from __future__ import annotations

import base64

import numpy as np

from .rendering import QUANTITY_3D, outward_normals, surface_cells

#: the page's budget for the data of one view [bytes] (plotly.js itself takes 4.8 MB)
MAX_BYTES = 6_000_000


def _b64(a, dtype) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode("ascii")


def _clusters(xyz, used, target: int) -> np.ndarray:
    """Cluster number of each node (-1 for nodes not drawn): nodes snapped to a cubic grid fine enough
    to keep about ``target`` vertices."""
    pts = xyz[used]
    lo, ext = pts.min(axis=0), np.ptp(pts, axis=0)
    h = float(np.sqrt(np.sum(ext[:, None] * ext[None, :]) / 2.0 / target)) or 1.0  # surface area / target
    for _ in range(30):
        _, inv = np.unique(np.floor((pts - lo) / h).astype(np.int64), axis=0, return_inverse=True)
        if inv.max() + 1 <= target:
            break
        h *= 1.25
    out = np.full(len(xyz), -1, np.int64)
    out[used] = inv.ravel()
    return out


class Scene:
    """One scene: a model's surface, beams and outlines (and test points), with one displacement field
    per mode.

    ``nodes`` (n, 3) [m], ``tris`` (t, 3), ``lines`` (b, 2) node indices; ``outlines`` as the mode
    pictures take them (dicts with "kind", "label", "xy" or "xyz" in metres, "closed"), each point moving
    with the nearest node; ``points`` (p, 3) [m] test points with ``point_labels``."""

    def __init__(self, title: str, nodes, tris, lines=None, outlines=(), points=None, point_labels=None,
                 surface_opacity: float = 1.0):
        self.title, self.opacity = title, surface_opacity
        self.xyz = np.asarray(nodes, float)
        self.tris = np.asarray(tris, np.int64).reshape(-1, 3)
        self.lines = np.zeros((0, 2), np.int64) if lines is None else np.asarray(lines, np.int64).reshape(-1, 2)
        self.used = np.unique(np.concatenate([self.tris.ravel(), self.lines.ravel()]))
        self._kd = None
        self.outlines = [self._attach(o) for o in outlines]
        self.points = None if points is None else np.asarray(points, float).reshape(-1, 3)
        self.point_labels = [str(p) for p in (point_labels if point_labels is not None else [])]
        self.normals = outward_normals(self.xyz, self.tris)
        self.node_modes, self.point_modes = [], []

    @classmethod
    def of_model(cls, title: str, model, outlines=(), **kw) -> "Scene":
        tris, lines = surface_cells(model)
        return cls(title, model.nodes, tris, lines, outlines, **kw)

    def _tree(self):
        """A k-d tree of the drawn nodes (made once)."""
        if self._kd is None:
            from scipy.spatial import cKDTree

            self._kd = cKDTree(self.xyz[self.used])
        return self._kd

    def _attach(self, item) -> dict:
        pts = np.asarray(item.get("xyz", item.get("xy", [])), float)
        pts = pts.reshape(-1, 3) if "xyz" in item else pts.reshape(-1, 2)
        if pts.shape[1] == 2:
            pts = np.column_stack([pts, np.full(len(pts), float(np.mean(self.xyz[self.used, 2])))])
        near = self.used[self._tree().query(pts)[1]] if len(pts) else np.zeros(0, np.int64)
        return {"kind": item.get("kind", ""), "label": item.get("label") or "", "closed": bool(item.get("closed")),
                "xyz": pts, "node": near}

    def add_mode(self, shape=None, point_motion=None) -> "Scene":
        """One mode: ``shape`` the full-length 6-DOF/node vector (None: the surface stays still) and
        ``point_motion`` (p, 3) the test points' motion (None: still)."""
        self.node_modes.append(None if shape is None else np.asarray(shape, float).reshape(-1, 6)[:, :3])
        self.point_modes.append(None if point_motion is None else np.asarray(point_motion, float).reshape(-1, 3))
        return self

    def _nbytes(self, n_vertices: int) -> int:
        per_mode = n_vertices * 7 + (0 if self.points is None else len(self.points) * 6)
        return int(4 / 3 * (n_vertices * 12 + len(self.tris) * 12 + len(self.node_modes) * per_mode))

    def payload(self, max_bytes: int = MAX_BYTES) -> dict:
        """The scene as the page's script reads it (coarsened to fit ``max_bytes``)."""
        xyz, tris, lines, normals = self.xyz, self.tris, self.lines, self.normals
        n_drawn, keep = len(self.used), None
        if self._nbytes(n_drawn) > max_bytes and n_drawn:
            target = max(int(n_drawn * max_bytes / self._nbytes(n_drawn)), 200)
            keep = _clusters(xyz, self.used, target)
            n_c = int(keep.max()) + 1
            xyz, normals = self._mean(xyz, keep, n_c), self._mean(normals, keep, n_c)
            normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
            tris, lines = keep[tris], keep[lines]
            tris = np.unique(np.sort(tris[(tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2])
                                          & (tris[:, 0] != tris[:, 2])], axis=1), axis=0)
            lines = np.unique(np.sort(lines[lines[:, 0] != lines[:, 1]], axis=1), axis=0)
        else:
            n_c = len(xyz)
        modes = []
        for u, p in zip(self.node_modes, self.point_modes):
            modes.append(self._mode(u if keep is None or u is None else self._mean(u, keep, n_c), normals, p))
        outlines = [{**{k: o[k] for k in ("kind", "label", "closed")}, "xyz": (o["xyz"] * 1e3).round(4).tolist(),
                     "node": (o["node"] if keep is None else keep[o["node"]]).tolist()} for o in self.outlines]
        out = {"title": self.title, "nodes": _b64(xyz * 1e3, np.float32), "tris": _b64(tris, np.uint32),
               "lines": _b64(lines, np.uint32), "outlines": outlines, "modes": modes, "opacity": self.opacity,
               "coarsened": None if keep is None else [n_drawn, n_c]}
        if self.points is not None:
            out.update(points=_b64(self.points * 1e3, np.float32), point_labels=self.point_labels)
        return out

    @staticmethod
    def _mean(a, cluster, n_c) -> np.ndarray:
        sums = np.zeros((n_c, a.shape[1]))
        ok = cluster >= 0
        np.add.at(sums, cluster[ok], a[ok])
        return sums / np.maximum(np.bincount(cluster[ok], minlength=n_c), 1)[:, None]

    @staticmethod
    def _mode(u, normals, p) -> dict:
        """One mode's data: the surface's motion and colours over its largest motion, and the points'
        motion on the same scale (on their own where the surface is still)."""
        out = {}
        scale = float(np.abs(u).max() if u is not None else 0.0) or float(np.abs(p).max() if p is not None else 0.0)
        scale = scale or 1.0
        if u is not None:
            out["u"] = _b64(np.round(u / scale * 32767), np.int16)
            out["s"] = _b64(np.round(np.einsum("ij,ij->i", u, normals) / scale * 127), np.int8)
        if p is not None:
            out["p"] = _b64(np.round(np.clip(p / scale, -1.0, 1.0) * 32767), np.int16)
        return out


def mode_view(scenes, labels, amplitude: float = 0.1, max_bytes: int = MAX_BYTES) -> dict:
    """A view of ``scenes`` (side by side) through the modes ``labels`` (one per mode added to each
    scene); ``amplitude``: the largest motion drawn, as a fraction of the structure's largest extent
    (the reader's starting value)."""
    for s in scenes:
        if len(s.node_modes) != len(labels):
            raise ValueError(f"scene '{s.title}' has {len(s.node_modes)} modes for {len(labels)} labels")
    budget = max_bytes // max(len(scenes), 1)
    return {"scenes": [s.payload(budget) for s in scenes], "labels": list(labels), "amplitude": amplitude,
            "colour": QUANTITY_3D}


def shapes_view(title: str, model, outlines, shapes, labels, max_bytes: int = MAX_BYTES) -> dict:
    """A view of one model through its mode ``shapes`` (full-length columns, one per label)."""
    scene = Scene.of_model(title, model, outlines)
    for k in range(len(labels)):
        scene.add_mode(shapes[:, k])
    return mode_view([scene], labels, max_bytes=max_bytes)


def point_motion(values, dof_points, directions, n_points: int) -> np.ndarray:
    """(n_points, 3): the motion of each point from the values (n_dof,) measured along ``directions``
    (n_dof, 3) at the points ``dof_points`` (n_dof,) (indices into the points)."""
    out = np.zeros((n_points, 3))
    np.add.at(out, np.asarray(dof_points), np.asarray(values)[:, None] * np.asarray(directions))
    return out


def pair_view(model, model_shapes, outlines, test_modes, at_test, pairs) -> dict:
    """Test and model side by side through the ``pairs`` (:class:`pcbdyn.correlation.pairing.Pair`):
    the model's surface and the test points moving with it (``model_shapes`` full-length, one column
    per pair; ``at_test`` the same read at the test DOFs), and the test points moving with the measured
    shape over the model at rest, the test shape turned by its modal scale factor against the model so
    that both move in phase."""
    pts = test_modes.measured_points()
    idx = pts.index(test_modes.dofs.point_ids)
    dirs = test_modes.dofs.directions
    model_scene = Scene.of_model("model", model, outlines, points=pts.xyz, point_labels=pts.ids)
    test_scene = Scene.of_model("test", model, outlines, points=pts.xyz, point_labels=pts.ids,
                                surface_opacity=0.25)
    for j, p in enumerate(pairs):
        t, m = test_modes.shapes[:, p.test], at_test[:, j]
        msf = np.vdot(t, m) / (np.vdot(t, t) or 1.0)
        model_scene.add_mode(model_shapes[:, j], point_motion(m, idx, dirs, len(pts.xyz)))
        test_scene.add_mode(None, point_motion(np.real(t * msf), idx, dirs, len(pts.xyz)))
    labels = [f"test {p.test + 1} ({p.f_test:.1f} Hz) / model {p.model + 1} ({p.f_model:.1f} Hz), MAC {p.mac_combined:.2f}"
              for p in pairs]
    return mode_view([model_scene, test_scene], labels)


def scripts() -> list:
    """The JavaScript a page with views carries: plotly.js from the plotly wheel, then ``view3d.js``."""
    from importlib.resources import files

    return [(files("plotly") / "package_data" / "plotly.min.js").read_text(encoding="utf-8"),
            (files("pcbdyn.report") / "templates" / "view3d.js").read_text(encoding="utf-8")]
