"""World.write_obj and World.export_obj (embra_world_export_obj), read back: the `v` lines are the
world's positions bit for bit, a triangle mesh's `f` lines its triangles, and a hanging net's `l`
lines its links (examples/hanging_net.json: edges, no triangles), so an edge-only mesh renders."""

import json
import os

import pytest

import embra
from tent import flat


def read_obj(path):
    v, f, lines = [], [], []
    with open(path) as text:
        for line in text:
            tokens = line.split()
            if not tokens:
                continue
            if tokens[0] == "v":
                v.extend(float(t) for t in tokens[1:4])
            elif tokens[0] == "f":
                f.append(tuple(int(t) - 1 for t in tokens[1:]))
            elif tokens[0] == "l":
                lines.append(tuple(int(t) - 1 for t in tokens[1:]))
    return v, f, lines


def test_hanging_net_writes_its_links_as_lines(source_dir, tmp_path):
    scene = os.path.join(source_dir, "examples", "hanging_net.json")
    with open(scene) as f:
        edges = json.load(f)["bodies"][0]["mesh"]["edges"]
    with embra.World.load_file(scene) as w:
        w.step(20)
        path = tmp_path / "net.obj"
        w.write_obj(path)
        v, faces, lines = read_obj(path)
        assert len(v) == 3 * w.particle_count == 3 * 121
        assert v == list(flat(w.positions()))  # %.17g: every double exactly
        assert min(v[2::3]) < -0.01  # the net has sagged: these are the stepped positions
        assert faces == []
        (net,) = w.bodies()
        first, _ = w.body_particles(net)
        assert sorted(lines) == sorted((first + a, first + b) for a, b in edges)
        assert len(lines) == 220
        with open(path) as f:
            assert f.read() == w.export_obj()


def test_triangles_are_faces_and_an_added_link_joins_a_chain(tmp_path):
    with embra.World() as w:
        sheet = w.create_body([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], triangles=[(0, 1, 2), (1, 3, 2)])
        chain = w.create_body([(0, 0, 1), (0.1, 0, 1), (0.2, 0, 1)], edges=[(0, 1), (1, 2)])
        w.add_constraint("distance", (chain.first + 2, chain.first))  # a link the host adds closes it
        w.step(5)
        path = tmp_path / "two.obj"
        w.write_obj(str(path))
        v, faces, lines = read_obj(path)
        assert len(v) == 3 * 7 and v == list(flat(w.positions()))
        assert faces == [tuple(t) for t in flat_rows(w.body_triangles(sheet))]
        assert lines == [(4, 5), (4, 6), (5, 6)]
        assert "g body_0\n" in w.export_obj() and "g body_1\n" in w.export_obj()


def flat_rows(triangles):
    values = [int(x) for x in flat(triangles)]
    return [values[k:k + 3] for k in range(0, len(values), 3)]


def test_refusals_change_nothing(tmp_path):
    with embra.World() as w:
        w.create_body([(0, 0, 0), (1, 0, 0)], edges=[(0, 1)])
        before = w.save_json()
        missing = tmp_path / "no-such-folder" / "x.obj"
        with pytest.raises(embra.InvalidArgumentError, match="no-such-folder"):
            w.write_obj(missing)
        assert not missing.exists() and w.save_json() == before
    with pytest.raises(embra.EmbraError):
        w.export_obj()  # a closed world refuses
