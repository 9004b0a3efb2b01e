"""A scene's OBJ paths resolve against its folder (the file's folder for load_file, base_dir for
load_json) and may not leave it unless the host allows it (allow_paths_outside_base=True)."""

import json
import os

import pytest

import embra

OBJ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"  # one quad: 4 vertices, 2 triangles


def scene(obj_path):
    return json.dumps({
        "format": "embra-scene", "version": 1, "name": "obj_scene",
        "bodies": [{"name": "sheet", "mesh": {"obj": obj_path}, "material": {"mass": 0.5}}],
    })


@pytest.fixture
def folders(tmp_path):
    """tmp/outside.obj, tmp/scenes/inside.obj, and scenes that name each from tmp/scenes."""
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (tmp_path / "outside.obj").write_text(OBJ)
    (scenes / "inside.obj").write_text(OBJ)
    (scenes / "inside.json").write_text(scene("inside.obj"))
    (scenes / "outside.json").write_text(scene("../outside.obj"))
    (scenes / "absolute.json").write_text(scene(str(tmp_path / "outside.obj")))
    return tmp_path


def test_obj_paths_resolve_against_the_scenes_folder(folders, monkeypatch):
    monkeypatch.chdir(folders)  # not the scene's folder: a path relative to the process would miss
    scenes = folders / "scenes"
    with embra.World.load_file(scenes / "inside.json") as w:
        assert w.particle_count == 4
    with embra.World.load_json((scenes / "inside.json").read_text(), base_dir=scenes) as w:
        assert w.particle_count == 4
    with embra.World.load_json((scenes / "inside.json").read_text(), base_dir=str(scenes)) as w:
        assert w.particle_count == 4


@pytest.mark.parametrize("name", ["outside.json", "absolute.json"])
def test_obj_paths_outside_the_scenes_folder_are_refused_unless_allowed(folders, name):
    scenes = folders / "scenes"
    path = scenes / name
    text = path.read_text()
    obj = json.loads(text)["bodies"][0]["mesh"]["obj"]
    with pytest.raises(embra.EmbraError) as e:
        embra.World.load_file(path)
    assert str(e.value).startswith("embra_world_load_file: ") and obj in str(e.value)
    with pytest.raises(embra.EmbraError) as e:
        embra.World.load_json(text, base_dir=scenes)
    assert str(e.value).startswith("embra_world_load_json_with_options: ") and obj in str(e.value)
    # the host that trusts the scene says so
    with embra.World.load_file(path, allow_paths_outside_base=True) as w:
        assert w.particle_count == 4
    with embra.World.load_json(text, base_dir=scenes, allow_paths_outside_base=True) as w:
        assert w.particle_count == 4


def test_the_option_is_a_yes_or_no(folders):
    path = folders / "scenes" / "outside.json"
    for value in ("yes", 1, None):
        with pytest.raises(TypeError, match="allow_paths_outside_base"):
            embra.World.load_file(path, allow_paths_outside_base=value)
        with pytest.raises(TypeError, match="allow_paths_outside_base"):
            embra.World.load_json(path.read_text(), allow_paths_outside_base=value)
    o = embra.default_load_options()
    assert (o.version, o.allow_paths_outside_base, o.base_dir) == (1, 0, None)


def test_allowed_file_loads_read_the_file_and_report_a_missing_one(folders):
    with pytest.raises(FileNotFoundError):
        embra.World.load_file(folders / "scenes" / "missing.json", allow_paths_outside_base=True)
    with embra.World.load_file(os.path.relpath(folders / "scenes" / "inside.json"),
                               allow_paths_outside_base=True) as w:
        assert w.particle_count == 4
