"""Scenes pickle by recipe (what Ray ships to its workers), and the recipe must rebuild the scene
the driver has: arrays are copied when the scene is made, and a process that rebuilt a file's scene
before the file was edited loads it again instead of keeping the old one."""

import pickle

import numpy as np

import lumiere


def round_trip(scene):
    return pickle.loads(pickle.dumps(scene))


def test_a_scene_from_arrays_keeps_copies_of_them():
    vertices = np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], dtype=np.float32)
    triangles = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    ids = np.array([0, 1], dtype=np.uint32)
    normals = np.array([[0, 1, 0]] * 4, dtype=np.float32)
    scene = lumiere.Scene.from_arrays(vertices, triangles, materials=["a", {"name": "w", "ke": (1, 1, 1)}],
                                      material_ids=ids, normals=normals)
    # The caller reuses its buffers: neither the scene nor its pickles may change.
    vertices *= 2
    triangles[:] = 0
    ids[:] = 0
    normals[:] = 0
    assert round_trip(scene).fingerprint == scene.fingerprint
    assert round_trip(scene).info()["bounds"] == ([-1.0, 0.0, -1.0], [1.0, 0.0, 1.0])


def test_an_edited_file_is_loaded_again_where_its_old_scene_was_rebuilt(tmp_path):
    obj = tmp_path / "tri.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    before = lumiere.load(obj)
    assert round_trip(before).fingerprint == before.fingerprint
    obj.write_text("v 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n")
    after = lumiere.load(obj)
    assert after.fingerprint != before.fingerprint
    # This process rebuilt the old scene from the same path and emission: it must not reuse it.
    assert round_trip(after).fingerprint == after.fingerprint
    assert round_trip(after).info()["bounds"] == after.info()["bounds"]
