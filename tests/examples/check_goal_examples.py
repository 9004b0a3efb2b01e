#!/usr/bin/python3
"""The goal-set examples checked from what `embra run` writes, by arithmetic anyone can redo: no
code of the library is used, only final.json (the world as it stopped: masses, pins, loads,
positions), forces.json (the reactions, N) and the scene's own numbers.

usage: check_goal_examples.py EXAMPLE RUN_DIR
  cable_net_roof       the reactions sum to minus the total applied load (every node's weight
                       plus p x the plan area of every triangle) to 1e-9 of it; each rail's
                       reaction is normal to its rail (its part along the rail below 1e-9 of it);
                       the net is at rest.
  gridshell_chebyshev  every lath 0.5 m to 1e-6 relative; the grid rose into a doubly curved
                       dome (its rise; the total of the angle defects, the discrete Gaussian
                       curvature, positive; the crown's two midlines both arching); the angles
                       between the two families of laths changed (the net sheared) while no
                       lath stretched.
  plastic_hinge        the fold after unloading equals the plastic set by hand (the loaded fold
                       where the weight's moment falls to the plastic moment, less the yield
                       angle) to 1e-6 rad; the hinge's rest is the fold; at rest.
Prints the measured figures; exits 1 if a check fails."""
import json
import math
import sys


def sub(a, b):
    return [a[k] - b[k] for k in range(3)]


def add(a, b):
    return [a[k] + b[k] for k in range(3)]


def dot(a, b):
    return sum(a[k] * b[k] for k in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def scale(s, a):
    return [s * v for v in a]


failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def load(run):
    with open(f"{run}/final.json") as f:
        world = json.load(f)
    with open(f"{run}/forces.json") as f:
        forces = json.load(f)
    return world, forces


def particles(world):
    """World index of each body's vertex 0, and every particle's mass (bodies in order)."""
    first, masses = {}, []
    for b in world["bodies"]:
        first[b["name"]] = len(masses)
        masses.extend(b["mesh"]["masses"])
    return first, masses


def index(ref, first):
    return ref if isinstance(ref, int) else first[ref["body"]] + ref["vertex"]


def cable_net_roof(run):
    world, forces = load(run)
    first, masses = particles(world)
    x = world["state"]["positions"]
    g = world["solver"]["gravity"]
    total = [0.0, 0.0, 0.0]
    for m in masses:
        total = add(total, scale(m, g))
    plan = 0.0
    for l in world["area_loads"]:
        assert l["mode"] == "projected_area"
        a, b, c = (x[index(p, first)] for p in l["particles"])
        u = scale(1.0 / norm(l["direction"]), l["direction"])
        area = abs(dot(scale(0.5, cross(sub(b, a), sub(c, a))), u))  # projected on the plane normal to u
        plan += area
        total = add(total, scale(l["pressure"] * area, u))
    s = [0.0, 0.0, 0.0]
    for r in forces["reactions"]:
        s = add(s, r["force"])
    imbalance = norm(add(s, total)) / norm(total)
    print(f"total load {total[2]:.6f} N (vertical; plan area {plan:.12f} m^2), reactions sum "
          f"[{s[0]:.6g}, {s[1]:.6g}, {s[2]:.6f}] N")
    check(abs(plan - 100.0) < 1e-9, f"the net covers its 10 m x 10 m plan: {plan:.15g} m^2")
    check(imbalance < 1e-9, f"reactions + load = {imbalance:.3g} of the load (bound 1e-9)")
    rails = {}
    for p in world["pins"]:
        if p.get("support") == "line":
            rails[index(p["particle"], first)] = p["axis"]
    worst, count = 0.0, 0
    for r in forces["reactions"]:
        axis = rails.get(r["particle"])
        if axis is None:
            continue
        count += 1
        f = r["force"]
        worst = max(worst, abs(dot(f, axis)) / (norm(axis) * norm(f)))
    check(count == 36, f"{count} rail supports")
    check(worst < 1e-9, f"each rail's reaction along its rail: at most {worst:.3g} of the reaction (bound 1e-9)")
    v = world["state"]["velocities"]
    speed = max(norm(w) for w in v)
    check(speed < world["solver"]["settle_speed"], f"at rest: max speed {speed:.3g} m/s")


def gridshell_chebyshev(run):
    world, _ = load(run)
    first, _ = particles(world)
    x = world["state"]["positions"]
    batch = world["constraints"][0]
    edges = [[index(p, first) for p in e] for e in batch["particles"]]
    worst = max(abs(norm(sub(x[a], x[b])) - 0.5) / 0.5 for a, b in edges)
    check(worst < 1e-6, f"every one of {len(edges)} laths 0.5 m to {worst:.3g} relative (bound 1e-6)")
    # The nodes on the grid: a node's lath neighbours, by direction in the flat grid (the mesh's
    # vertices are the flat grid, body-local).
    flat = world["bodies"][0]["mesh"]["vertices"]
    key = {(round(p[0] / 0.5), round(p[1] / 0.5)): k for k, p in enumerate(flat)}
    rise = max(p[2] for p in x) - min(p[2] for p in x)
    check(rise > 0.5, f"the dome rises {rise:.4f} m over its ground beam")
    defects, shear = [], 0.0
    for (i, j), k in key.items():
        around = [key.get((i + 1, j)), key.get((i, j + 1)), key.get((i - 1, j)), key.get((i, j - 1))]
        if None in around:
            continue
        angles = []
        for m in range(4):
            e, f = sub(x[around[m]], x[k]), sub(x[around[(m + 1) % 4]], x[k])
            angles.append(math.acos(max(-1.0, min(1.0, dot(e, f) / (norm(e) * norm(f))))))
        defects.append(2 * math.pi - sum(angles))
        shear = max(shear, max(abs(t - 0.5 * math.pi) for t in angles))
    positive = sum(1 for d in defects if d > 0.0)
    check(sum(defects) > 0.5, f"total Gaussian curvature (sum of the angle defects 2 pi - sum of the four angles "
          f"at the {len(defects)} interior nodes; 0 for any developable sheet) {sum(defects):.4f} rad; "
          f"positive at {positive} nodes")
    # The crown: the grid's two midlines through it both arch (second differences of z along each,
    # per the lath length squared, negative), so its Gaussian curvature is positive there.
    z = lambda i, j: x[key[(i, j)]][2]  # noqa: E731
    kx = (z(1, 0) + z(-1, 0) - 2 * z(0, 0)) / 0.25
    ky = (z(0, 1) + z(0, -1) - 2 * z(0, 0)) / 0.25
    check(kx < 0.0 and ky < 0.0, f"the crown is synclastic: curvature along the laths {kx:.4f} and {ky:.4f} 1/m "
          f"(Gaussian curvature {kx * ky:.4f} 1/m^2)")
    check(math.degrees(shear) > 10.0, f"the grid sheared: the angle between the families departs from 90 degrees "
          f"by up to {math.degrees(shear):.2f} degrees (flat: 0)")


def plastic_hinge(run):
    world, _ = load(run)
    first, masses = particles(world)
    x = world["state"]["positions"]
    hinge = next(b for b in world["constraints"] if b["kind"] == "dihedral")
    a, b, c, d = (index(p, first) for p in hinge["particles"][0])
    alpha, yield_angle = hinge["compliance"][0], hinge["yield"][0]
    # The fold: the angle between the fixed plate (a, b, c) and the flap (b, a, d) across a-b.
    e = sub(x[b], x[a])
    u = e if norm(e) == 0 else scale(1.0 / norm(e), e)
    def across(p):  # the part of p - a normal to the hinge line
        v = sub(x[p], x[a])
        return sub(v, scale(dot(v, u), u))
    pc, pd = across(c), across(d)
    r = norm(pd)
    fold = math.pi - math.acos(dot(pc, pd) / (norm(pc) * norm(pd)))
    g = max(norm(k["value"]) for act in world["actions"] if act["type"] == "gravity" for k in act["keys"])
    m = masses[d]
    # By hand: loaded, the weight's moment m g r cos(phi) about the hinge falls to the plastic moment
    # yield / compliance where the flow stops; unloaded, the hinge springs back by the yield angle.
    loaded = math.acos(yield_angle / (alpha * m * g * r))
    by_hand = loaded - yield_angle
    print(f"flap {m} kg at r = {r:.12f} m, compliance {alpha} rad/(N m), yield {yield_angle} rad, g {g} m/s^2: "
          f"loaded fold {math.degrees(loaded):.6f} deg, set by hand {by_hand:.9f} rad")
    check(abs(fold - by_hand) < 1e-6, f"fold after unloading {fold:.9f} rad = the plastic set by hand to "
          f"{abs(fold - by_hand):.3g} rad (bound 1e-6)")
    check(abs(abs(hinge["rest"][0]) - fold) < 1e-9, f"the hinge's rest followed it: rest {hinge['rest'][0]:.9f} rad, "
          f"fold {fold:.9f} rad ({abs(abs(hinge['rest'][0]) - fold):.3g} apart, bound 1e-9)")
    speed = max(norm(w) for w in world["state"]["velocities"])
    check(speed < world["solver"]["settle_speed"], f"at rest: max speed {speed:.3g} m/s")


if __name__ == "__main__":
    {"cable_net_roof": cable_net_roof, "gridshell_chebyshev": gridshell_chebyshev,
     "plastic_hinge": plastic_hinge}[sys.argv[1]](sys.argv[2])
    sys.exit(1 if failures else 0)
