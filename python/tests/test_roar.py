"""The Python package against the installed wheel: arrays in and out, errors, progress,
Ctrl-C, the GIL released while roar works, glTF files written by trimesh, and a Dask map."""

import functools
import os
import pathlib
import threading
import _thread

import numpy as np
import pytest
import trimesh

import roar

REPO = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "chair_soup.obj"

# Toy settings (as the Rust pipeline tests use): seconds, not minutes.
TOY = {
    "target": {
        "views_per_axis": 2,
        "render_resolution": 64,
        "point_cloud_samples": 5000,
        "sharp_edge_samples": 1000,
    },
    "init": {"init_resolution": 32, "init_max_faces": 4000},
    "loss": {"planar_max_samples": 5000},
    "optimize": {
        "iterations": 6,
        "working_budget_min": 600,
        "split_interval": 3,
        "smoothing_interval": 2,
    },
}


def example():
    mesh = trimesh.load(EXAMPLE, process=False, force="mesh")
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def signed_volume(vertices, faces):
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def test_round_trip_with_trimesh():
    v, f = example()
    out_v, out_f, report = roar.reconstruct(v, f, target_faces=200, config=TOY)
    assert out_v.dtype == np.float64 and out_v.shape[1] == 3
    assert out_f.dtype == np.int64 and out_f.shape == (200, 3)
    mesh = trimesh.Trimesh(out_v, out_f, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume > 0
    assert report["output_metrics"]["topology"]["faces"] == 200
    assert report["input"] == "<arrays>"
    assert report["config"]["optimize"]["iterations"] == TOY["optimize"]["iterations"]
    # Same seed, same input: the same mesh, from any accepted dtype.
    again = roar.reconstruct(v.astype(np.float64), f.astype(np.uint32), 200, config=TOY)
    assert np.array_equal(again[0], out_v) and np.array_equal(again[1], out_f)


def test_every_accepted_dtype_reads_the_same_soup():
    v, f = example()
    v32 = v.astype(np.float32)
    reports = [
        roar.eval(v32, f.astype(dtype)) for dtype in (np.int32, np.int64, np.uint32)
    ]
    assert reports[0] == reports[1] == reports[2]
    assert reports[0]["topology"]["faces"] == len(f)


@pytest.mark.parametrize(
    "vertices, faces, message",
    [
        (np.zeros((4, 2)), np.array([[0, 1, 2]]), "shape (n, 3)"),
        (np.zeros((4, 3), dtype=np.int64), np.array([[0, 1, 2]]), "float32 or float64"),
        (np.zeros((4, 3)), np.array([[0, 1, 2]], dtype=np.float64), "int32, int64 or uint32"),
        (np.zeros((4, 3)), np.array([0, 1, 2]), "shape (m, 3)"),
        (np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]]), np.array([[0, 1, 2]]), "vertex 2"),
        (np.zeros((3, 3)), np.array([[0, 1, 3]]), "index 3 out of range"),
        (np.zeros((3, 3)), np.array([[0, -1, 2]]), "index -1 out of range"),
        (np.zeros((3, 3)), np.zeros((0, 3), dtype=np.int64), "no triangles"),
    ],
)
def test_bad_arrays_raise_value_error_before_any_work(vertices, faces, message):
    calls = []
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        roar.reconstruct(vertices, faces, 200, config=TOY, progress=calls.append)
    assert calls == []


def test_bad_config_and_budget_raise_value_error():
    v, f = example()
    with pytest.raises(ValueError, match="unknown field"):
        roar.reconstruct(v, f, 200, config={"no_such_key": 1})
    with pytest.raises(ValueError, match=r"belongs in the \[loss\] table"):
        roar.reconstruct(v, f, 200, config={"render_weight": 1.0})
    with pytest.raises(ValueError, match="config"):
        roar.reconstruct(v, f, 201, config=TOY)
    with pytest.raises(ValueError, match="target_faces"):
        roar.reconstruct(v, f, 0)


def test_errors_carry_the_cli_message(tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(roar.RoarError, match=str(missing)):
        roar.reconstruct_file(missing, 200, config=TOY)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(roar.RoarError) as info:
        roar.reconstruct_file(bad, 200, config=TOY)
    assert str(info.value).startswith(f"{bad}:2:")
    assert "\n" not in str(info.value)


def test_progress_gets_the_cli_records_and_its_exception_stops_the_run():
    v, f = example()
    records = []
    roar.reconstruct(v, f, 200, config=TOY, progress=records.append)
    stages = [r["stage"] for r in records]
    for stage in ("target", "init", "optimize", "decimate"):
        assert stage in stages
    optimize = [r for r in records if r["stage"] == "optimize"]
    assert [r["iteration"] for r in optimize] == list(range(TOY["optimize"]["iterations"]))
    assert all(set(r) == {"stage", "iteration", "iterations", "loss", "faces"} for r in records)

    class Stop(Exception):
        pass

    def stop_at_optimize(record):
        if record["stage"] == "optimize":
            raise Stop("enough")

    with pytest.raises(Stop):
        roar.reconstruct(v, f, 200, config=TOY, progress=stop_at_optimize)


def test_ctrl_c_raises_keyboard_interrupt_and_stops_the_run():
    v, f = example()
    # All 500 iterations run unless interrupted (no stop when the loss levels off).
    long_run = dict(TOY, optimize=dict(TOY["optimize"], iterations=500, level_window=0))
    optimize = []

    def on_progress(record):
        if record["stage"] == "optimize":
            optimize.append(record["iteration"])
            if len(optimize) == 1:
                # As a terminal's Ctrl-C: SIGINT arrives from outside the running call.
                threading.Thread(target=_thread.interrupt_main).start()

    with pytest.raises(KeyboardInterrupt):
        roar.reconstruct(v, f, 200, config=long_run, progress=on_progress)
    assert len(optimize) < long_run["optimize"]["iterations"]


def test_another_thread_runs_while_roar_works():
    v, f = example()
    counter = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counter[0] += 1

    seen = []
    thread = threading.Thread(target=count)
    thread.start()
    try:
        roar.reconstruct(v, f, 200, config=TOY, progress=lambda r: seen.append(counter[0]))
    finally:
        stop.set()
        thread.join()
    # The counter advanced between the first and the last progress report, i.e. while roar's
    # stages ran (with the GIL held throughout, the counting thread would barely run).
    assert seen[-1] > seen[0]


def test_decimate_and_init():
    sphere = trimesh.creation.icosphere(subdivisions=3)
    v, f = roar.decimate(sphere.vertices, sphere.faces, 100)
    assert f.shape == (100, 3)
    assert trimesh.Trimesh(v, f, process=False).is_watertight
    with pytest.raises(ValueError, match="closed, oriented 2-manifold"):
        roar.decimate(sphere.vertices, sphere.faces[:-1], 100)
    ex_v, ex_f = example()
    v, f = roar.init(ex_v, ex_f, resolution=32, max_faces=2000)
    init = trimesh.Trimesh(v, f, process=False)
    assert init.is_watertight and init.volume > 0 and len(f) <= 2000
    assert roar.default_config()["faces"] > 0


def gltf_scene():
    """A box and an icosphere under nested nodes, the sphere mirrored by a negative scale."""
    scene = trimesh.Scene()
    box = trimesh.creation.box(extents=(1.0, 2.0, 0.5))
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.5)
    scene.add_geometry(box, node_name="box", transform=trimesh.transformations.translation_matrix([2, 0, 0]))
    parent = trimesh.transformations.rotation_matrix(0.3, [0, 0, 1])
    scene.graph.update(frame_to="parent", frame_from=scene.graph.base_frame, matrix=parent)
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    mirror[:3, 3] = [0.0, 1.5, 0.0]
    scene.add_geometry(sphere, node_name="sphere", parent_node_name="parent", transform=mirror)
    return scene, box.volume + sphere.volume


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_gltf_written_by_trimesh(tmp_path, suffix):
    scene, volume = gltf_scene()
    path = tmp_path / f"scene{suffix}"
    if suffix == ".glb":
        path.write_bytes(scene.export(file_type="glb"))
    else:
        files = scene.export(file_type="gltf")
        for name, data in files.items():
            (tmp_path / ("scene.gltf" if name == "model.gltf" else name)).write_bytes(data)
    v, f = roar.read_mesh(path)
    # trimesh's own reading of its file, flattened into one soup.
    expected = trimesh.load(path, force="scene").to_geometry()
    assert len(f) == len(expected.faces)
    got = np.sort(v[f].reshape(-1, 3).round(5), axis=0)
    want = np.sort(np.asarray(expected.vertices)[expected.faces].reshape(-1, 3).round(5), axis=0)
    assert np.allclose(got, want, atol=1e-5)
    # Both closed parts face outward after the mirror: their volumes add up.
    assert signed_volume(v, f) == pytest.approx(volume, rel=1e-5)
    out_v, out_f, report = roar.reconstruct_file(path, 200, config=TOY)
    assert out_f.shape == (200, 3) and report["input"] == str(path)


def test_dask_map_over_files_on_a_local_cluster(tmp_path):
    from dask.distributed import Client, LocalCluster

    paths = [str(EXAMPLE)]
    sphere = tmp_path / "sphere.ply"
    trimesh.creation.icosphere(subdivisions=3).export(sphere)
    paths.append(str(sphere))
    task = functools.partial(roar.reconstruct_file, target_faces=200, config=TOY)
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        results = client.gather(client.map(task, paths))
    assert [r[2]["input"] for r in results] == paths
    for v, f, _ in results:
        assert f.shape == (200, 3)
        assert trimesh.Trimesh(v, f, process=False).is_watertight


# Toy settings of the SDF schedule (as the Rust SDF tests use), with the SDF loss on halfway.
SDF_TOY = {
    "target": dict(TOY["target"], sdf_trace_grid=64),
    "loss": dict(TOY["loss"], sdf_loss_start=15),
    "optimize": dict(TOY["optimize"], iterations=30),
}
# The field evaluations a run may spend: marching cubes 128³'s count.
EVALUATION_CAP = 2_100_000
TORUS_BOUNDS = ((-0.8, -0.8, -0.35), (0.8, 0.8, 0.35))


def torus(p):
    """The exact signed distance of a torus (radii 0.5 and 0.2) about z, genus 1."""
    ring = np.hypot(p[:, 0], p[:, 1]) - 0.5
    return np.hypot(ring, p[:, 2]) - 0.2


def torus_gradient(p):
    xy = np.maximum(np.hypot(p[:, 0], p[:, 1]), 1e-12)
    ring = xy - 0.5
    d = np.maximum(np.hypot(ring, p[:, 2]), 1e-12)
    return np.stack([ring / d * p[:, 0] / xy, ring / d * p[:, 1] / xy, p[:, 2] / d], axis=1)


class Mlp:
    """A bumpy sphere: |p| − 0.5 plus 0.05 × a 3→32→32→1 tanh network with fixed random
    weights, and its gradient by backpropagation, both in numpy."""

    def __init__(self, seed=3):
        rng = np.random.default_rng(seed)
        self.w1, self.b1 = rng.normal(0, 2.0, (3, 32)), rng.normal(0, 0.5, 32)
        self.w2, self.b2 = rng.normal(0, 0.3, (32, 32)), rng.normal(0, 0.5, 32)
        self.w3 = rng.normal(0, 0.3, 32)

    def _forward(self, p):
        h1 = np.tanh(p @ self.w1 + self.b1)
        h2 = np.tanh(h1 @ self.w2 + self.b2)
        return h1, h2, np.tanh(h2 @ self.w3)

    def __call__(self, p):
        return np.linalg.norm(p, axis=1) - 0.5 + 0.05 * self._forward(p)[2]

    def gradient(self, p):
        h1, h2, out = self._forward(p)
        d2 = np.outer(1 - out**2, self.w3) * (1 - h2**2)
        d1 = (d2 @ self.w2.T) * (1 - h1**2)
        radial = p / np.maximum(np.linalg.norm(p, axis=1, keepdims=True), 1e-12)
        return radial + 0.05 * d1 @ self.w1.T


def field_evaluations(report):
    sdf = report["sdf"]
    return sum(sdf["values"].values()) + sum(sdf["gradients"].values())


def check_closed_output(v, f, faces):
    assert f.shape == (faces, 3)
    metrics = roar.eval(v, f)
    assert metrics["self_intersections"]["faces"] == 0
    return trimesh.Trimesh(v, f, process=False)


def test_mlp_gradient_matches_finite_differences():
    mlp = Mlp()
    p = np.random.default_rng(0).uniform(-0.7, 0.7, (50, 3))
    h = 1e-6
    fd = np.stack(
        [(mlp(p + h * e) - mlp(p - h * e)) / (2 * h) for e in np.eye(3)], axis=1
    )
    assert np.allclose(mlp.gradient(p), fd, atol=1e-6)


def test_reconstruct_sdf_of_a_numpy_function_without_gradient():
    batches = []

    def f(p):
        batches.append(len(p))
        return torus(p)

    v, faces, report = roar.reconstruct_sdf(f, TORUS_BOUNDS, 1000, config=SDF_TOY)
    mesh = check_closed_output(v, faces, 1000)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.euler_number == 0  # genus 1
    # Only the sampling calls the field, for values alone, in batches of at most 16,384.
    sdf = report["sdf"]
    assert set(k for k, n in sdf["values"].items() if n) == {"sample"}
    assert sum(sdf["gradients"].values()) == 0
    assert sum(batches) == field_evaluations(report) <= EVALUATION_CAP
    assert max(batches) <= 16384
    assert report["sdf"]["sample"]["field_gradients"] is False
    # The output lies on the zero set (the toy schedule's 15 iterations of SDF loss: within
    # 2.5 % of the tube's radius), as close as with the field's own gradient.
    off = np.abs(torus(v)).mean()
    assert off < 0.005
    v, _, report = roar.reconstruct_sdf(
        torus, TORUS_BOUNDS, 1000, gradient=torus_gradient, config=SDF_TOY
    )
    assert report["sdf"]["sample"]["field_gradients"] is True
    assert off < 1.25 * np.abs(torus(v)).mean()


def test_reconstruct_sdf_of_a_numpy_mlp_with_its_gradient():
    mlp = Mlp()
    bounds = ((-0.75,) * 3, (0.75,) * 3)
    v, faces, report = roar.reconstruct_sdf(
        mlp, bounds, 1000, gradient=mlp.gradient, config=SDF_TOY
    )
    mesh = check_closed_output(v, faces, 1000)
    assert mesh.is_watertight and mesh.euler_number == 2
    sdf = report["sdf"]
    assert sum(sdf["values"].values()) == 0
    assert 0 < field_evaluations(report) <= EVALUATION_CAP
    assert report["sdf"]["sample"]["field_gradients"] is True
    first_order = np.abs(mlp(v)) / np.linalg.norm(mlp.gradient(v), axis=1)
    assert first_order.mean() < 0.005


class FieldBroke(Exception):
    pass


@pytest.mark.parametrize(
    "f, error, message",
    [
        (lambda p: (_ for _ in ()).throw(FieldBroke("inside f")), FieldBroke, "inside f"),
        (lambda p: torus(p)[:-1], ValueError, r"f: batch 0 \(\d+ points\): returned shape"),
        (
            lambda p: np.where(p[:, 0] > 0.7, np.nan, torus(p)),
            ValueError,
            r"f: batch \d+ \(\d+ points\): not finite at point \d+",
        ),
        (lambda p: ["x"] * len(p), ValueError, "cannot read the result as float64"),
    ],
)
def test_errors_of_the_field_are_raised_as_themselves_or_name_the_batch(f, error, message):
    with pytest.raises(error, match=message):
        roar.reconstruct_sdf(f, TORUS_BOUNDS, 1000, config=SDF_TOY)


def test_an_unsampled_field_needs_its_gradient():
    calls = []
    unsampled = dict(SDF_TOY, target=dict(SDF_TOY["target"], sdf_sample=False))
    with pytest.raises(ValueError, match="sdf_sample = false .* give `gradient`"):
        roar.reconstruct_sdf(lambda p: calls.append(1) or torus(p), TORUS_BOUNDS, 1000, config=unsampled)
    assert calls == []


def test_a_wrong_gradient_shape_names_the_batch():
    with pytest.raises(ValueError, match=r"gradient: batch 0 .* expected \(\d+, 3\)"):
        roar.reconstruct_sdf(
            torus, TORUS_BOUNDS, 1000, gradient=lambda p: p[:, :2], config=SDF_TOY
        )


@pytest.mark.parametrize(
    "bounds",
    [((0, 0, 0), (1, 1)), ((0, 0, 0), (1, 0, 1)), ((0, 0, np.nan), (1, 1, 1)), "box"],
)
def test_bad_bounds_raise_value_error_before_any_call(bounds):
    calls = []
    with pytest.raises(ValueError, match="bounds"):
        roar.reconstruct_sdf(lambda p: calls.append(1) or torus(p), bounds, 1000)
    assert calls == []
