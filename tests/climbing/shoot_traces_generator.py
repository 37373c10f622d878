#!/usr/bin/python3
"""Synthetic time-lapse traces of a climbing plant on a wall, written
independently of phytocal (no phytocal code or binary is called) from the
description of the growth process in Hadrich, Benes, Deussen, Pirk,
"Interactive Modeling and Authoring of Climbing Plants", CGF 36(2) 2017,
sections 4.2-4.3:

* every apex advances along its direction at speed v_k = r a^k L (r the
  growth rate in 1/s, a the apical dominance, k the branch order, L the
  internode length in m);
* when an apex has grown a full internode it leaves a node; at the node one
  bud becomes a lateral shoot with probability BP (unless k = max_order),
  leaving at an angle theta = u V 90 degrees (u uniform in [0, 1)) to the
  parent at a uniform azimuth;
* phototropism turns an apex toward the light direction l by the fraction
  eta dt of the angle between them per step; surface adaption turns it by
  tau dt toward the closest point of the wall (the plane y = 0, |x| <= 0.5,
  0 <= z <= 1.2) when that is within the adaption radius; an apex within
  the contact distance that heads into the wall loses the inward part of
  its direction (it crawls along the wall).

The apex positions are written every `--interval` seconds, plus each node
when it is laid down; columns time (s), shoot, x, y, z (m), parent.  The
numbers are synthetic: they are NOT measurements of a real plant.

With `--rsml OUT.rsml` the same traces are also written as RSML 1.0
(Lobet et al. 2015; unit m, resolution 1): one <root> per shoot, laterals
nested in their parent, the points of a shoot in the CSV's order with the
same digits, and each point's time as a per-point function named "time"
(domain polyline, s), the convention measurements/shoot_traces.h reads.

Usage: shoot_traces_generator.py OUT.csv [--rsml OUT.rsml] [--seed N] [--duration S] ...
"""
import argparse
import math
import random


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def turn_toward(d, target, frac):
    """Rotate unit d toward unit target by frac of the angle between them."""
    frac = max(0.0, min(1.0, frac))
    c = max(-1.0, min(1.0, sum(a * b for a, b in zip(d, target))))
    ang = math.acos(c)
    if ang < 1e-12:
        return d
    # slerp
    s = math.sin(ang)
    t = frac * ang
    w0 = math.sin(ang - t) / s
    w1 = math.sin(t) / s
    return unit([w0 * a + w1 * b for a, b in zip(d, target)])


def perpendicular(d):
    a = [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0]
    p = [d[1] * a[2] - d[2] * a[1], d[2] * a[0] - d[0] * a[2], d[0] * a[1] - d[1] * a[0]]
    return unit(p)


def lateral_direction(d, theta, phi):
    e1 = perpendicular(d)
    e2 = [d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2], d[0] * e1[1] - d[1] * e1[0]]
    return unit([math.cos(theta) * d[i] + math.sin(theta) * (math.cos(phi) * e1[i] + math.sin(phi) * e2[i])
                 for i in range(3)])


def closest_on_wall(p):
    return [max(-0.5, min(0.5, p[0])), 0.0, max(0.0, min(1.2, p[2]))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--rsml", help="also write the traces as RSML to this file")
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--duration", type=float, default=120.0)
    ap.add_argument("--dt", type=float, default=0.25)
    ap.add_argument("--interval", type=float, default=10.0)
    ap.add_argument("--internode", type=float, default=0.02)
    ap.add_argument("--growth-rate", type=float, default=0.2)
    ap.add_argument("--apical-dominance", type=float, default=0.6)
    ap.add_argument("--branch-probability", type=float, default=0.3)
    ap.add_argument("--variance", type=float, default=0.6)
    ap.add_argument("--max-order", type=int, default=2)
    ap.add_argument("--phototropism", type=float, default=0.02)
    ap.add_argument("--surface-adaption", type=float, default=0.5)
    ap.add_argument("--adaption-radius", type=float, default=0.1)
    ap.add_argument("--contact-distance", type=float, default=0.004)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    light = unit([0.0, 1.0, 2.0])
    # shoots: name, parent, order, apex position, direction, grown length of the current internode
    shoots = [{"name": "s0", "parent": "", "order": 0, "x": [0.0, 0.03, 0.0], "d": [0.0, 0.0, 1.0], "g": 0.0}]
    rows = [(0.0, "s0", shoots[0]["x"][:], "")]
    t = 0.0
    steps = int(round(args.duration / args.dt))
    every = int(round(args.interval / args.dt))
    for step in range(1, steps + 1):
        t = step * args.dt
        born = []
        for s in shoots:
            d = turn_toward(s["d"], light, args.phototropism * args.dt)
            c = closest_on_wall(s["x"])
            to = [c[i] - s["x"][i] for i in range(3)]
            dist = math.sqrt(sum(v * v for v in to))
            if 1e-12 < dist <= args.adaption_radius:
                d = turn_toward(d, unit(to), args.surface_adaption * args.dt)
            if dist <= args.contact_distance and d[1] < 0:  # heading into the wall (normal +y)
                d = unit([d[0], 0.0, d[2]]) if abs(d[0]) + abs(d[2]) > 1e-12 else d
            s["d"] = d
            v = args.growth_rate * args.apical_dominance ** s["order"] * args.internode
            step_len = v * args.dt
            s["x"] = [s["x"][i] + step_len * d[i] for i in range(3)]
            s["g"] += step_len
            if s["g"] >= args.internode:  # a node
                s["g"] -= args.internode
                rows.append((t, s["name"], s["x"][:], s["parent"]))
                if s["order"] < args.max_order and rng.random() < args.branch_probability:
                    theta = rng.random() * args.variance * math.pi / 2
                    phi = rng.random() * 2 * math.pi
                    name = "s%d" % (len(shoots) + len(born))
                    born.append({"name": name, "parent": s["name"], "order": s["order"] + 1, "x": s["x"][:],
                                 "d": lateral_direction(d, theta, phi), "g": 0.0})
                    rows.append((t, name, s["x"][:], s["name"]))
        shoots.extend(born)
        if step % every == 0:
            for s in shoots:
                if s["g"] > 0:
                    rows.append((t, s["name"], s["x"][:], s["parent"]))
    with open(args.out, "w") as f:
        f.write("# SYNTHETIC traces written by tests/climbing/shoot_traces_generator.py (seed %d):\n"
                "# not measurements of a real plant.  time s; x, y, z m (wall face y = 0, z up)\n" % args.seed)
        f.write("time,shoot,x,y,z,parent\n")
        # a shoot needs 2 points: drop laterals born too late to be traced twice
        count = {}
        for r in rows:
            count[r[1]] = count.get(r[1], 0) + 1
        kept = {n for n, c in count.items() if c >= 2}
        written = []
        for tt, name, x, parent in rows:
            if name in kept and (parent == "" or parent in kept):
                f.write("%g,%s,%.6f,%.6f,%.6f,%s\n" % (tt, name, x[0], x[1], x[2], parent))
                written.append((tt, name, x, parent))
    if args.rsml:
        write_rsml(args.rsml, written, args.seed)


def write_rsml(path, rows, seed):
    """The rows (time, shoot, x, parent) as RSML: shoots nested by parent."""
    order, points, parent_of = [], {}, {}
    for tt, name, x, parent in rows:
        if name not in points:
            order.append(name)
            points[name] = []
            parent_of[name] = parent
        points[name].append((tt, x))
    children = {n: [c for c in order if parent_of[c] == n] for n in order}
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           '<!-- SYNTHETIC traces written by tests/climbing/shoot_traces_generator.py (seed %d): '
           'not measurements of a real plant -->' % seed,
           '<rsml>', '  <metadata>', '    <version>1</version>', '    <unit>m</unit>',
           '    <resolution>1</resolution>', '    <software>shoot_traces_generator.py</software>',
           '  </metadata>', '  <scene>', '    <plant id="1">']

    def root(name, depth):
        pad = "  " * depth
        out.append('%s<root id="%s">' % (pad, name))
        out.append('%s  <geometry>' % pad)
        out.append('%s    <polyline>' % pad)
        for tt, x in points[name]:
            out.append('%s      <point x="%.6f" y="%.6f" z="%.6f"/>' % (pad, x[0], x[1], x[2]))
        out.append('%s    </polyline>' % pad)
        out.append('%s  </geometry>' % pad)
        out.append('%s  <functions>' % pad)
        out.append('%s    <function name="time" domain="polyline">' % pad)
        for tt, x in points[name]:
            out.append('%s      <sample>%g</sample>' % (pad, tt))
        out.append('%s    </function>' % pad)
        out.append('%s  </functions>' % pad)
        for c in children[name]:
            root(c, depth + 1)
        out.append('%s</root>' % pad)

    for n in order:
        if parent_of[n] == "":
            root(n, 3)
    out += ['    </plant>', '  </scene>', '</rsml>']
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
