"""The quadlod Python module (issue 22): arrays in and out, the CLI's answers, errors as exceptions.

Run by CTest (test `python_module`) with PYTHONPATH=build/python and QUADLOD_CLI set; by hand:
  PYTHONPATH=build/python QUADLOD_CLI=build/quadlod /usr/bin/python3 -m pytest tests/python
"""

import os
import subprocess

import numpy as np
import pytest

import quadlod

CLI = os.environ.get("QUADLOD_CLI")


def torus(n=24, m=12, major=1.0, minor=0.35):
    """An n × m all-quad torus with per-corner UVs (a seam along u = 0 and v = 0) and two
    materials (the faces of the first half of the rings use slot 0, the rest slot 1)."""
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    u, v = 2 * np.pi * i / n, 2 * np.pi * j / m
    vertices = np.stack([(major + minor * np.cos(v)) * np.cos(u),
                         (major + minor * np.cos(v)) * np.sin(u),
                         minor * np.sin(v)], axis=-1).reshape(-1, 3)
    vid = lambda a, b: (a % n) * m + (b % m)  # noqa: E731
    quads, uvs = [], []
    for a in range(n):
        for b in range(m):
            quads.append([vid(a, b), vid(a + 1, b), vid(a + 1, b + 1), vid(a, b + 1)])
            uvs.extend([(a / n, b / m), ((a + 1) / n, b / m), ((a + 1) / n, (b + 1) / m), (a / n, (b + 1) / m)])
    quads = np.array(quads, dtype=np.int64)
    materials = (np.arange(n * m) // m >= n // 2).astype(np.int32)
    return vertices, quads, np.array(uvs), materials


def tri_equivalents(sizes):
    return int(np.sum(np.asarray(sizes) - 2))


def check_layout(result):
    sizes, corners, vertices = result["face_sizes"], result["faces"], result["vertices"]
    assert vertices.ndim == 2 and vertices.shape[1] == 3
    assert sizes.sum() == len(corners)
    assert corners.min() >= 0 and corners.max() < len(vertices)
    assert np.all(sizes >= 3)


def test_simplify_reaches_the_target_and_keeps_quads():
    vertices, quads, _, _ = torus()
    r = quadlod.simplify(vertices, quads, ratio=0.5)
    check_layout(r)
    rep = r["report"]
    assert rep["input_tri_equivalent"] == 2 * len(quads)
    assert rep["target"] == len(quads)  # half of 2 per quad
    assert rep["achieved"] == tri_equivalents(r["face_sizes"])
    assert abs(rep["achieved"] - rep["target"]) <= 0.03 * rep["target"]  # Eq. 2's band, ε_n = 3 %
    # The torus halves mostly by collapsing whole poly-chords: it stays quad-dominant (measured:
    # 142 of 146 faces are quads).
    assert np.mean(r["face_sizes"] == 4) >= 0.9
    assert rep["quads"] == np.sum(r["face_sizes"] == 4)
    assert rep["triangles"] == np.sum(r["face_sizes"] == 3)


def test_effort_plans_passes_and_is_deterministic():
    vertices, quads, _, _ = torus()
    base = quadlod.simplify(vertices, quads, ratio=0.4)
    more = quadlod.simplify(vertices, quads, ratio=0.4, effort=2.0)
    assert base["report"]["passes_planned"] == 9  # ceil(log 0.4 / log 0.9)
    assert more["report"]["passes_planned"] == 18  # twice the passes
    again = quadlod.simplify(vertices, quads, ratio=0.4, effort=2.0)
    assert np.array_equal(more["vertices"], again["vertices"])
    assert np.array_equal(more["faces"], again["faces"])
    with pytest.raises(quadlod.QuadlodError):
        quadlod.simplify(vertices, quads, ratio=0.4, effort=0.0)


def test_face_forms_and_dtypes_give_the_same_mesh():
    vertices, quads, _, _ = torus()
    a = quadlod.simplify(vertices, quads, ratio=0.5)
    # Blender's dtypes (float32 coordinates, int32 loops) read as the same numbers in float64.
    flat = (quads.ravel().astype(np.int32), np.full(len(quads), 4, dtype=np.int32))
    b = quadlod.simplify(vertices.astype(np.float32), flat, ratio=0.5)
    b_ref = quadlod.simplify(vertices.astype(np.float32).astype(np.float64), quads, ratio=0.5)
    # Plain lists are converted by NumPy.
    c = quadlod.simplify(vertices.tolist(), (list(quads.ravel()), [4] * len(quads)), ratio=0.5)
    for got, want in ((b, b_ref), (c, a)):
        np.testing.assert_array_equal(got["faces"], want["faces"])
        np.testing.assert_array_equal(got["face_sizes"], want["face_sizes"])
        np.testing.assert_array_equal(got["vertices"], want["vertices"])
    # Strided (non-contiguous) views are read in place.
    wide = np.zeros((len(vertices), 6))
    wide[:, ::2] = vertices
    d = quadlod.simplify(wide[:, ::2], quads, ratio=0.5)
    np.testing.assert_array_equal(a["vertices"], d["vertices"])


def test_faces_target_counts_triangle_equivalents():
    vertices, quads, _, _ = torus()
    r = quadlod.simplify(vertices, quads, faces_target=300)
    assert r["report"]["target"] == 300
    assert abs(r["report"]["achieved"] - 300) <= 0.03 * 300


def test_uvs_and_materials_come_back_per_corner_and_per_face():
    vertices, quads, uvs, materials = torus()
    r = quadlod.simplify(vertices, quads, ratio=0.5, uvs={"UVMap": uvs, "Second": uvs * 2}, materials=materials)
    check_layout(r)
    assert set(r["uvs"]) == {"UVMap", "Second"}
    for layer in r["uvs"].values():
        assert layer.shape == (len(r["faces"]), 2)
        assert np.all(np.isfinite(layer))
    np.testing.assert_allclose(r["uvs"]["Second"], 2 * r["uvs"]["UVMap"], rtol=0, atol=1e-12)
    assert r["materials"].shape == r["face_sizes"].shape
    assert set(np.unique(r["materials"])) == {0, 1}
    single = quadlod.simplify(vertices, quads, ratio=0.5, uvs=uvs)
    assert isinstance(single["uvs"], np.ndarray) and single["uvs"].shape == (len(single["faces"]), 2)


def test_lod_chain_reduces_each_level_from_the_previous():
    vertices, quads, uvs, materials = torus()
    chain = quadlod.lod_chain(vertices, quads, levels=3, ratio=0.5, uvs=uvs, materials=materials)
    assert len(chain) == 3
    full = 2 * len(quads)
    for k, level in enumerate(chain, start=1):
        check_layout(level)
        assert level["report"]["target"] == round(full * 0.5 ** k)
        assert abs(level["report"]["achieved"] - level["report"]["target"]) <= 0.03 * level["report"]["target"] + 2
    # Level 2 is the reduction of level 1's output: the same as simplify() on it.
    first = chain[0]
    again = quadlod.simplify(first["vertices"], (first["faces"], first["face_sizes"]),
                             faces_target=chain[1]["report"]["target"], uvs=first["uvs"], materials=first["materials"])
    np.testing.assert_array_equal(again["faces"], chain[1]["faces"])
    np.testing.assert_array_equal(again["vertices"], chain[1]["vertices"])
    explicit = quadlod.lod_chain(vertices, quads, ratios=[0.5, 0.25, 0.125], uvs=uvs, materials=materials)
    np.testing.assert_array_equal(explicit[2]["faces"], chain[2]["faces"])
    # Each level measured against the input (the library's lod_chain, docs/lod.md): a coarser
    # level strays further and may only be shown smaller on screen.
    errors = [level["hausdorff"] for level in chain]
    sizes = [level["screen_size"] for level in chain]
    assert 0 < errors[0] <= errors[1] <= errors[2]
    assert 1 >= sizes[0] >= sizes[1] >= sizes[2] > 0
    unmeasured = quadlod.lod_chain(vertices, quads, levels=1, measure_hausdorff=False)
    assert np.isnan(unmeasured[0]["hausdorff"])
    with pytest.raises(ValueError):
        quadlod.lod_chain(vertices, quads, ratios=[0.5, 0.5])


def test_evaluate_matches_the_definitions_on_known_answers():
    vertices, quads, _, _ = torus()
    same = quadlod.evaluate((vertices, quads), (vertices, quads), samples=5000)
    assert same["chamfer"] == pytest.approx(0.0, abs=1e-12)
    assert same["hausdorff"] == pytest.approx(0.0, abs=1e-12)
    assert same["quads_in"] == same["quads_out"] == len(quads)
    r = quadlod.simplify(vertices, quads, ratio=0.5)
    metrics = quadlod.evaluate((vertices, quads), r, samples=5000)
    assert metrics["tri_equivalent_out"] == r["report"]["achieved"]
    assert metrics["quads_out"] == r["report"]["quads"]
    assert 0 < metrics["chamfer"] < metrics["hausdorff"] < 0.2
    assert metrics["validity"]["nonmanifold_edges"] == 0


def test_errors_are_exceptions_with_the_library_message():
    vertices, quads, _, _ = torus()
    bad = vertices.copy()
    bad[2, 1] = np.nan
    with pytest.raises(quadlod.QuadlodError, match=r"^vertex 3 \(1-based\) has a non-finite coordinate$"):
        quadlod.simplify(bad, quads, ratio=0.5)
    out_of_range = quads.copy()
    out_of_range[5, 2] = len(vertices)
    with pytest.raises(quadlod.QuadlodError, match="out of range"):
        quadlod.simplify(vertices, out_of_range, ratio=0.5)
    with pytest.raises(quadlod.QuadlodError, match="face_sizes add up to"):
        quadlod.simplify(vertices, (quads.ravel(), [4] * (len(quads) - 1)), ratio=0.5)
    with pytest.raises(quadlod.QuadlodError, match="uvs: 3 rows"):
        quadlod.simplify(vertices, quads, ratio=0.5, uvs=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="give a target"):
        quadlod.simplify(vertices, quads)
    with pytest.raises(ValueError, match="ratio"):
        quadlod.simplify(vertices, quads, ratio=1.5)
    with pytest.raises(TypeError, match="faces_target: an integer"):
        quadlod.simplify(vertices, quads, faces_target="many")
    with pytest.raises(TypeError, match="option 'seed': wrong type"):
        quadlod.simplify(vertices, quads, ratio=0.5, seed="x")
    with pytest.raises(TypeError, match="unknown option 'no_such_option'"):
        quadlod.simplify(vertices, quads, ratio=0.5, no_such_option=1)
    assert issubclass(quadlod.QuadlodError, ValueError)


def test_surface_fit_options_reach_the_fit():
    """The CLI's --surface-fit and --surface-fit-vertex-weight, with its ranges."""
    vertices, quads, _, _ = torus()
    default = quadlod.simplify(vertices, quads, ratio=0.4)
    assert default["report"]["surface_fit"]["iterations"] == 2  # on by default (simplify.h)
    assert default["report"]["surface_fit"]["vertex_weight"] == 0.0
    off = quadlod.simplify(vertices, quads, ratio=0.4, surface_fit=0)
    assert "surface_fit" not in off["report"]
    np.testing.assert_array_equal(off["faces"], default["faces"])  # the fit moves vertices only
    assert not np.array_equal(off["vertices"], default["vertices"])
    peak = quadlod.simplify(vertices, quads, ratio=0.4, surface_fit_vertex_weight=0.25)
    assert peak["report"]["surface_fit"]["vertex_weight"] == 0.25
    with pytest.raises(ValueError, match=r"surface_fit: 101"):
        quadlod.simplify(vertices, quads, ratio=0.4, surface_fit=101)
    with pytest.raises(ValueError, match="surface_fit_vertex_weight"):
        quadlod.simplify(vertices, quads, ratio=0.4, surface_fit_vertex_weight=-1.0)
    # --decide-on-doubles: the torus's float64 coordinates are not float32 values, so by default
    # the decisions are made on them rounded, and the report says so; with the option, on them as given.
    doubles = quadlod.simplify(vertices, quads, ratio=0.4, decide_on_doubles=True)
    assert default["report"]["float32_decisions"] is True
    assert "float32_decisions" not in doubles["report"]


def test_an_all_triangle_input_gets_its_quads_back():
    """recover_quads (the CLI's --recover-quads): auto joins the triangle pairs of a triangulated mesh."""
    vertices, quads, _, _ = torus()
    tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    r = quadlod.simplify(vertices, tris, ratio=0.5)
    assert r["report"]["quad_recovery"]["quads_made"] == len(quads)
    assert np.mean(r["face_sizes"] == 4) >= 0.9
    off = quadlod.simplify(vertices, tris, ratio=0.5, recover_quads="off")
    assert "quad_recovery" not in off["report"]
    assert np.all(off["face_sizes"] == 3)
    with pytest.raises(ValueError, match="recover_quads: 'auto', 'on' or 'off', not 'yes'"):
        quadlod.simplify(vertices, tris, ratio=0.5, recover_quads="yes")


def test_seams_policy_reaches_the_reduction():
    """seams (the CLI's --seams): lone triangles meet a budget only by letting small parts vanish,
    which auto allows once a pass stalls and strict never does."""
    vertices, faces = [], []
    for k in range(50):
        x, y = 2.0 * (k % 10), 2.0 * (k // 10)
        vertices += [[x, y, 0.0], [x + 1, y, 0.0], [x + 1, y + 1, 0.0]]
        faces.append([3 * k, 3 * k + 1, 3 * k + 2])
    vertices, faces = np.array(vertices), np.array(faces)
    auto = quadlod.simplify(vertices, faces, ratio=0.4)
    assert auto["report"]["seams"]["policy"] == "auto"
    assert auto["report"]["achieved"] == 20
    strict = quadlod.simplify(vertices, faces, ratio=0.4, seams="strict")
    assert strict["report"]["seams"]["policy"] == "strict"
    assert strict["report"]["achieved"] == 50
    assert "with --seams strict" in strict["report"]["note"]
    with pytest.raises(ValueError, match="seams: 'auto' or 'strict', not 'loose'"):
        quadlod.simplify(vertices, faces, ratio=0.4, seams="loose")


def test_symmetry_keeps_a_mirrored_mesh_mirrored():
    """symmetry (the CLI's --symmetry, issue 34): a grid bent symmetrically about x = 0 reduces to
    a mesh whose every vertex has its mirror image; jittered, it gets the note and off's output."""
    n, m = 16, 12
    xs, ys = np.meshgrid(np.linspace(-1.0, 1.0, n + 1), np.linspace(-0.75, 0.75, m + 1))
    zs = 0.3 * np.exp(-3.0 * (xs ** 2 + ys ** 2)) + 0.15 * ys + 0.05 * xs ** 2
    vertices = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    faces = np.array([[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i]
                      for j in range(m) for i in range(n)])
    for symmetry in ("auto", "x"):
        r = quadlod.simplify(vertices, faces, ratio=0.4, symmetry=symmetry)
        assert r["report"]["symmetry"]["axis"] == "x"
        v = r["vertices"]
        mirrored = v * np.array([-1.0, 1.0, 1.0])
        gaps = np.min(np.linalg.norm(v[:, None, :] - mirrored[None, :, :], axis=2), axis=1)
        assert np.max(gaps) <= 1e-9 * 2.5
    jittered = vertices + np.random.default_rng(34).uniform(-0.02, 0.02, vertices.shape) * np.array([0, 0, 1])
    off = quadlod.simplify(jittered, faces, ratio=0.4, symmetry="off")
    auto = quadlod.simplify(jittered, faces, ratio=0.4, symmetry="auto")
    assert "not mirror-symmetric" in auto["report"]["symmetry"]["note"]
    assert np.array_equal(auto["vertices"], off["vertices"]) and np.array_equal(auto["faces"], off["faces"])
    with pytest.raises(ValueError, match="symmetry: 'auto', 'x', 'y', 'z' or 'off', not 'w'"):
        quadlod.simplify(vertices, faces, ratio=0.4, symmetry="w")


def test_morph_targets_are_carried_exactly_where_vertices_survive():
    """Blend shapes (issue 34): morph_targets={name: (V, 3)} in, the same names out, one
    displacement per output vertex; an output vertex at an input vertex's position carries that
    vertex's displacement exactly, and the lod chain carries them level by level."""
    n = 16  # a flat n × n grid of quads over the unit square: vertices that stay, stay exactly
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    vertices = np.stack([i / n, j / n, 0 * i], axis=-1).reshape(-1, 3).astype(float)
    vid = lambda a, b: a * (n + 1) + b  # noqa: E731
    quads = np.array([[vid(a, b), vid(a + 1, b), vid(a + 1, b + 1), vid(a, b + 1)]
                      for a in range(n) for b in range(n)])
    lift = np.zeros_like(vertices)
    lift[:, 2] = 0.1 * vertices[:, 0]  # linear in x: any interpolation gives 0.1 x back
    twist = np.zeros_like(vertices)
    twist[vid(5, 8)] = [0.0, 0.05, 0.2]
    r = quadlod.simplify(vertices, quads, ratio=0.4, morph_targets={"lift": lift, "twist": twist})
    check_layout(r)
    assert list(r["morph_targets"]) == ["lift", "twist"]
    assert r["report"]["morph_targets"] == {"count": 2, "names": ["lift", "twist"]}
    out = r["vertices"]
    for name in ("lift", "twist"):
        assert r["morph_targets"][name].shape == out.shape
    survivors = 0
    for v, p in enumerate(out):
        same = np.flatnonzero(np.all(vertices == p, axis=1))
        if len(same):
            survivors += 1
            np.testing.assert_array_equal(r["morph_targets"]["lift"][v], lift[same[0]])
            np.testing.assert_array_equal(r["morph_targets"]["twist"][v], twist[same[0]])
    assert survivors >= 10
    np.testing.assert_allclose(r["morph_targets"]["lift"][:, 2], 0.1 * out[:, 0], atol=1e-12)
    chain = quadlod.lod_chain(vertices, quads, ratios=[0.5, 0.25], morph_targets={"lift": lift},
                              measure_hausdorff=False, morph_weight=2.0)
    for level in chain:
        assert list(level["morph_targets"]) == ["lift"]
        np.testing.assert_allclose(level["morph_targets"]["lift"][:, 2], 0.1 * level["vertices"][:, 0], atol=1e-12)
        assert level["report"]["options"]["morph_error_weight"] == 2.0
    with pytest.raises(ValueError, match=r"morph_targets\['lift'\]: 3 rows for 289 vertices"):
        quadlod.simplify(vertices, quads, ratio=0.4, morph_targets={"lift": lift[:3]})
    with pytest.raises(ValueError, match="morph_weight"):
        quadlod.simplify(vertices, quads, ratio=0.4, morph_weight=-1.0)


def test_the_input_arrays_are_not_modified():
    vertices, quads, uvs, materials = torus()
    copies = [a.copy() for a in (vertices, quads, uvs, materials)]
    quadlod.simplify(vertices, quads, ratio=0.3, uvs=uvs, materials=materials)
    for before, after in zip(copies, (vertices, quads, uvs, materials)):
        np.testing.assert_array_equal(before, after)


@pytest.mark.skipif(not CLI, reason="QUADLOD_CLI not set (CTest sets it)")
def test_same_output_as_the_cli(tmp_path):
    """The module and `quadlod simplify` give the same mesh for the same file and options."""
    source, reduced = tmp_path / "vase.obj", tmp_path / "vase_40.obj"
    subprocess.run([CLI, "generate", "vase", "-o", str(source)], check=True, capture_output=True)
    subprocess.run([CLI, "-q", "simplify", str(source), "-o", str(reduced), "--ratio", "0.4"],
                   check=True, capture_output=True)
    m = quadlod.read_mesh(str(source))
    r = quadlod.simplify(m["vertices"], (m["faces"], m["face_sizes"]), ratio=0.4, uvs=m.get("uvs"),
                         normals=m.get("normals"), materials=m.get("materials"))
    expected = quadlod.read_mesh(str(reduced))
    np.testing.assert_array_equal(r["face_sizes"], expected["face_sizes"])
    np.testing.assert_array_equal(r["faces"], expected["faces"])
    np.testing.assert_allclose(r["vertices"], expected["vertices"], rtol=0, atol=1e-8)  # OBJ's 9 digits
    # And the write → read round trip of the module's own writer.
    written = tmp_path / "module.obj"
    quadlod.write_mesh(r, str(written))
    np.testing.assert_array_equal(quadlod.read_mesh(str(written))["faces"], expected["faces"])


@pytest.mark.skipif(not CLI, reason="QUADLOD_CLI not set (CTest sets it)")
def test_read_errors_carry_the_cli_message(tmp_path):
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    cli = subprocess.run([CLI, "info", str(broken)], capture_output=True, text=True)
    assert cli.returncode == 2
    with pytest.raises(quadlod.QuadlodError) as error:
        quadlod.read_mesh(str(broken))
    assert cli.stderr.strip() == "quadlod: " + str(error.value)


CORPUS = os.environ.get("QUADLOD_CORPUS_DIR", "")


@pytest.mark.skipif(not CLI, reason="QUADLOD_CLI not set (CTest sets it)")
@pytest.mark.parametrize("name", ["collada_duck", "flightgear_head_amelia"])
def test_same_output_as_the_cli_on_corpus_meshes_with_uvs(tmp_path, name):
    """Corpus meshes with UVs (and the duck's normals): OBJ's shared UV / normal pools become one
    entry per corner in the module, and the output is still the CLI's, UVs included."""
    source = os.path.join(CORPUS, name + ".obj")
    if not os.path.exists(source):
        pytest.skip(f"{source} not present (../shared/corpus)")
    reduced = tmp_path / "out.obj"
    subprocess.run([CLI, "-q", "simplify", source, "-o", str(reduced), "--ratio", "0.5"], check=True, capture_output=True)
    m = quadlod.read_mesh(source)
    r = quadlod.simplify(m["vertices"], (m["faces"], m["face_sizes"]), ratio=0.5, uvs=m.get("uvs"),
                         normals=m.get("normals"))
    expected = quadlod.read_mesh(str(reduced))
    np.testing.assert_array_equal(r["faces"], expected["faces"])
    np.testing.assert_array_equal(r["face_sizes"], expected["face_sizes"])
    np.testing.assert_allclose(r["vertices"], expected["vertices"], rtol=0, atol=1e-6)
    (got,), (want,) = r["uvs"].values(), expected["uvs"].values()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-6)


def test_protect_keeps_weight_one_vertices_exactly():
    """Issue 34 (docs/protect.md): protect= weights — the weight-1 vertices (a band of the torus)
    come out at their exact input positions, the output's weights follow its vertices, and a bad
    array is the library's one-line error."""
    vertices, quads, _, _ = torus(32, 16)
    weights = (vertices[:, 0] > 0.9).astype(float)  # a band of 1 on the far side of the torus
    weights[(vertices[:, 1] > 0.8)] = 0.5
    assert 0.1 < np.mean(weights == 1.0) < 0.3
    r = quadlod.simplify(vertices, quads, ratio=0.3, protect=weights)
    out = {tuple(p) for p in r["vertices"]}
    protected = vertices[weights == 1.0]
    assert all(tuple(p) in out for p in protected)
    assert len(r["protect"]) == len(r["vertices"])
    assert int(np.sum(r["protect"] == 1.0)) == len(protected)
    assert abs(r["report"]["achieved"] - r["report"]["target"]) <= 0.03 * r["report"]["target"]
    assert r["report"]["protect"]["protected_vertices"] == len(protected)
    # Without weights the band is reduced like the rest.
    plain = {tuple(p) for p in quadlod.simplify(vertices, quads, ratio=0.3)["vertices"]}
    assert sum(tuple(p) not in plain for p in protected) > len(protected) // 4
    with pytest.raises(quadlod.QuadlodError, match="protect weight of vertex 3 is 2"):
        bad = np.zeros(len(vertices))
        bad[3] = 2.0
        quadlod.simplify(vertices, quads, ratio=0.3, protect=bad)
    with pytest.raises(quadlod.QuadlodError, match="protect weights for"):
        quadlod.simplify(vertices, quads, ratio=0.3, protect=np.zeros(5))
    with pytest.raises(TypeError, match="protect"):
        quadlod.simplify(vertices, quads, ratio=0.3, protect=np.zeros((5, 2)))
