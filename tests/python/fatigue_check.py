#!/usr/bin/env python3
"""Independent check of clutchpack's fatigue counting and damage (MODEL.md section 7).

    py=$(bash tests/python/setup.sh)
    "$py" tests/python/fatigue_check.py RUN.mcap CYCLES.json SUMMARY.json SCENE.toml

From the RECORDING alone (decoded with the official MCAP packages), it rebuilds each disc's
per-tooth load history by the documented rule (docs/DECISIONS.md, "Fatigue"):
  - lumped: 0, then per impact (by onset) either its peak (a pulse) or, when at least 4
    non-zero samples lie strictly inside (t_on, t_off), those samples with the located peak
    merged in by time; then 0;
  - resolved teeth: 0, then tooth k's load at every recorded sample;
counts them with the PyPI `rainflow` package (ASTM E1049-85, residue as half cycles, no
binning) and requires the (range, count) lists to EQUAL those clutchpack wrote with
`run --fatigue-json` (CYCLES.json). Then it sums Miner's damage with numpy from its own counts
and the scene's tooth form and material (read from SCENE.toml with tomllib, the defaults
written here independently), with the root stress sigma = cos(alpha) / (b m) Y_F Y_S K_l
|dF| / 2 and Basquin with a knee (original / elementary / Haibach 2k - 1), and requires the
damage of every disc and tooth in `run --summary-json` (SUMMARY.json) to agree to 1e-12
relative. Exit 0 with a one-line report on stdout, 1 with the reason on stderr.
"""

import json
import math
import sys
import tomllib

import numpy as np
import rainflow
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from mcap_ros2.decoder import DecoderFactory as Ros2DecoderFactory

SUSTAINED = 4
REL = 1e-12
# ASSUMED defaults of docs/DECISIONS.md, "Fatigue" (written here, not read from the program)
FORM = {"form_factor": 2.1, "stress_correction_factor": 2.0,
        "load_distribution_factor": 1.0, "face_width_m": 3e-3, "working_depth_m": 2.7e-3}
MATERIAL = {"endurance_amplitude_pa": 315e6, "knee_cycles": 3e6, "slope": 6.2,
            "miner_rule": "haibach", "critical_damage": 1.0}


def fail(msg):
    print(f"fatigue_check.py: {msg}", file=sys.stderr)
    sys.exit(1)


def read(path):
    impacts, loads, teeth = {}, {}, {}
    with open(path, "rb") as f:
        # every topic is decoded (the ROS 2 /joints for Rerun too); impacts are taken from
        # /impacts only, as /discs/<disc>/impacts repeats them per disc
        for schema, channel, message, m in make_reader(
                f, decoder_factories=[DecoderFactory(), Ros2DecoderFactory()]
        ).iter_decoded_messages():
            name = schema.name
            if name == "clutchpack.Impact" and channel.topic == "/impacts":
                impacts.setdefault(m.disc_index, []).append(
                    (m.t_on_s, m.t_peak_s, m.t_off_s, m.peak_n))
            elif name == "clutchpack.SplineState":
                loads.setdefault(m.disc_index, []).append((m.t_s, m.load_n))
            elif name == "clutchpack.ToothLoads":
                teeth.setdefault(m.disc_index, []).append((m.t_s, list(m.loads_n)))
    for d in (loads, teeth):
        for v in d.values():
            v.sort(key=lambda s: s[0])
    return impacts, loads, teeth


def lumped_history(events, samples):
    h = [0.0]
    for t_on, t_peak, t_off, peak in sorted(events, key=lambda e: e[0]):
        inside = [(t, x) for t, x in samples if t_on < t < t_off and x != 0.0]
        if len(inside) >= SUSTAINED:
            before = [x for t, x in inside if t <= t_peak]
            after = [x for t, x in inside if t > t_peak]
            h += before + [peak] + after
        else:
            h.append(peak)
        h.append(0.0)
    return h


def counts(history):
    return [(float(r), float(n)) for r, n in rainflow.count_cycles(history)]


def params(scene, i):
    disc = scene.get("discs", [])[i] if i < len(scene.get("discs", [])) else {}
    d = scene.get("defaults", {})
    get = lambda t, k, dflt: disc.get(t, {}).get(k, d.get(t, {}).get(k, dflt))
    sp = {k: get("spline", k, None) for k in ("teeth", "pitch_radius_m", "pressure_angle_deg")}
    form = {k: get("fatigue", k, v) for k, v in FORM.items()}
    mat = {k: get("material", k, v) for k, v in MATERIAL.items()}
    m = 2.0 * sp["pitch_radius_m"] / sp["teeth"]
    c = (math.cos(math.radians(sp["pressure_angle_deg"])) / (form["face_width_m"] * m)
         * form["form_factor"] * form["stress_correction_factor"]
         * form["load_distribution_factor"])
    return c, mat


def miner(ranges, c, mat):
    if not ranges:
        return 0.0
    r = np.array([x[0] for x in ranges])
    n = np.array([x[1] for x in ranges])
    s = c * r / 2.0
    sd, nd, k = mat["endurance_amplitude_pa"], mat["knee_cycles"], mat["slope"]
    below = {"original": math.inf, "elementary": k, "haibach": 2 * k - 1}[mat["miner_rule"]]
    with np.errstate(divide="ignore"):
        ratio = sd / s
    exp = np.where(s >= sd, k, below)
    life = np.where(np.isinf(exp) | (s == 0), np.inf, nd * ratio ** np.where(np.isinf(exp), 1, exp))
    return float(np.sum(n / life))


def close(a, b):
    return a == b or abs(a - b) <= REL * max(abs(a), abs(b))


def main():
    if len(sys.argv) != 5:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    mcap_path, cycles_path, summary_path, scene_path = sys.argv[1:]
    impacts, loads, teeth = read(mcap_path)
    cycles = json.load(open(cycles_path))
    summary = json.load(open(summary_path))
    scene = tomllib.load(open(scene_path, "rb"))
    n_cycles = n_teeth = 0
    for i, disc in enumerate(cycles):
        fat = summary["fatigue"][i]
        h = lumped_history(impacts.get(i, []), loads.get(i, []))
        mine = counts(h)
        theirs = [tuple(x) for x in disc["ranges"]]
        if mine != theirs:
            fail(f"disc {disc['name']}: lumped counts differ: rainflow {mine[:5]}... "
                 f"clutchpack {theirs[:5]}... ({len(mine)} vs {len(theirs)} ranges)")
        if abs(sum(n for _, n in mine) - fat["cycles"]) > 1e-9:
            fail(f"disc {disc['name']}: cycle total {fat['cycles']} != {sum(n for _, n in mine)}")
        span = max(h) - min(h)
        if mine and mine[-1][0] != span:
            fail(f"disc {disc['name']}: largest range {mine[-1][0]} != peak-to-valley {span}")
        c, mat = params(scene, i)
        d = miner(mine, c, mat)
        if not close(d, fat["damage"]):
            fail(f"disc {disc['name']}: damage {fat['damage']!r} != numpy Miner {d!r}")
        n_cycles += len(mine)
        tl = teeth.get(i, [])
        if disc["teeth_ranges"]:
            if not tl:
                fail(f"disc {disc['name']}: per-tooth ranges but no per-tooth loads recorded")
            for k, theirs_k in enumerate(disc["teeth_ranges"]):
                hk = [0.0] + [loads_n[k] for _, loads_n in tl]
                mine_k = counts(hk)
                if mine_k != [tuple(x) for x in theirs_k]:
                    fail(f"disc {disc['name']} tooth {k}: counts differ")
                dk = miner(mine_k, c, mat)
                if not close(dk, fat["teeth"]["damage"][k]):
                    fail(f"disc {disc['name']} tooth {k}: damage "
                         f"{fat['teeth']['damage'][k]!r} != numpy Miner {dk!r}")
                n_teeth += 1
    print(f"ok: {len(cycles)} discs, {n_cycles} distinct lumped ranges, {n_teeth} teeth: "
          f"counts equal rainflow {rainflow.__version__ if hasattr(rainflow, '__version__') else ''}, "
          f"damage equal to {REL:g}")


if __name__ == "__main__":
    main()
