#!/usr/bin/env python3
"""The FMU checked from outside with FMPy (issue 23), run by tests/fmu.rs:

    "$py" tests/python/fmu_check.py --bin CLUTCHPACK --root REPO --work DIR CHECK

CHECK is one of:
- validate: `clutchpack fmu` of every shipped scene, then FMPy's validate_fmu on each FMU
  built; prints {scene: {"built", "message", "problems"}}.
- paper: FMPy's simulate_fmu drives the paper case's FMU with the sine of Table 2 sampled at
  every 1e-5 s communication point, recording to an MCAP; `clutchpack run` runs the same
  scene with that held speed as a table (drive.interpolation = "hold"). Prints both impact
  lists and whether `clutchpack replay` read the recording.
- coupling: a Python master (FMPy's FMU2Slave) couples the paper case's FMU (a prescribed
  shaft) to a shaft inertia it integrates itself, J1 dw/dt = T_drive + T_pack, at several
  communication steps; `clutchpack run` runs the same pack with shaft.mode = "inertial".
  Prints the impact lists of each.
- rollback: get the FMU's state, advance, set the state, advance again; prints both output
  histories.
- network_packs: the same with both clutches resolved packs, driven by their pistons' pressures
- network: the DCT upshift's FMU (a network scene): its inputs, FMPy's validation, the shift
  driven by the clutch forces' schedule through FMPy against `clutchpack run`
- network_speed: the FMU of a network with a prescribed motor (tests/prescribed_pack.rs's
  MOTOR, given on the command line's --scene-text): its inputs with their units and start
  values, a NaN speed refused (fmi2Error), the motor's angle after its speed is set to
  30 rad/s at t = 0 and advanced 0.1 s twice.
- thermal: pack-8-idle-thermal with a steady drive (drive.amplitude_rad_s = 0, so the FMU's
  inputs held at their start values are the scene's own profiles) for 0.5 s: FMPy's
  simulate_fmu reads every temperature output at the end; `clutchpack run` of the same
  scene writes its final temperatures to --summary-json. Prints both, and the temperature
  outputs' units and whether the description has them.

Every result is JSON on stdout; the assertions and their bounds are in tests/fmu.rs.
"""

import argparse
import contextlib
import csv
import io
import json
import math
import os
import shutil
import subprocess
import sys

import fmpy
import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

# Table 2's drive (scenes/hu-table2.toml)
OMEGA0, AMPLITUDE, FREQUENCY = 200.0, 4.378, 104.0
DURATION = 0.05


def speed(t):
    return OMEGA0 + AMPLITUDE * np.sin(2 * np.pi * FREQUENCY * t)


def run(args, *cmd):
    p = subprocess.run([args.bin, *cmd], capture_output=True, text=True, cwd=args.root)
    if p.returncode != 0:
        raise SystemExit(f"clutchpack {' '.join(cmd)}: exit {p.returncode}: {p.stderr}")
    return p


def build(args, scene, out, *extra):
    return subprocess.run(
        [args.bin, "fmu", scene, "--out", out, *extra],
        capture_output=True,
        text=True,
        cwd=args.root,
    )


def read_impacts(path, exported):
    """Impacts as (body, t_on, t_peak, t_off, peak) from a run's --impacts-csv or an
    export's impacts.csv."""
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append(
                [r["disc"], float(r["t_on_s"]), float(r["t_peak_s"]), float(r["t_off_s"]),
                 float(r["peak_n"])]
            )
    return rows


def recorded_impacts(args, mcap, work, name):
    out = os.path.join(work, name)
    run(args, "export", mcap, "--csv", out)
    return read_impacts(os.path.join(out, "impacts.csv"), True)


def paper_scene(args, work, name, drive):
    """The paper case with its [drive] table replaced by `drive` (TOML lines)."""
    src = open(os.path.join(args.root, "scenes/hu-table2.toml")).read().splitlines()
    out, skip = [], False
    for line in src:
        if line.startswith("["):
            skip = line.strip() == "[drive]"
            if skip:
                out.append("[drive]")
                out.extend(drive)
                continue
        if not skip:
            out.append(line)
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    return path


def check_validate(args):
    work = args.work
    result = {}
    for name in sorted(os.listdir(os.path.join(args.root, "scenes"))):
        if not name.endswith(".toml"):
            continue
        fmu = os.path.join(work, name.replace(".toml", ".fmu"))
        p = build(args, os.path.join("scenes", name), fmu)
        entry = {"built": p.returncode == 0, "exit": p.returncode,
                 "message": (p.stdout + p.stderr).strip()}
        if p.returncode == 0:
            entry["problems"] = validate_fmu(fmu)
        result[name] = entry
    return result


def check_paper(args):
    work, h = args.work, 1e-5
    fmu = os.path.join(work, "hu-table2.fmu")
    p = build(args, "scenes/hu-table2.toml", fmu)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    t = np.arange(0, DURATION + h / 2, h)
    u = np.zeros(len(t), dtype=[("time", float), ("shaft.speed_rad_s", float)])
    u["time"], u["shaft.speed_rad_s"] = t, speed(t)
    mcap = os.path.join(work, "paper-fmu.mcap")
    r = fmpy.simulate_fmu(
        fmu,
        stop_time=DURATION,
        output_interval=h,
        input=u,
        start_values={"recording_path": mcap},
        output=["impacts", "discs[1].max_load_n", "discs[1].damage"],
    )
    # the same held speed as a scene: one row per communication point
    table = os.path.join(work, "held.csv")
    rows = t[t < DURATION - h / 2]
    with open(table, "w") as f:
        f.write("time_s,speed_rad_s\n")
        for ti in rows:
            f.write(f"{float(ti)!r},{float(speed(ti))!r}\n")
    scene = paper_scene(args, work, "held.toml",
                        ['kind = "speed_table"', 'file = "held.csv"', 'interpolation = "hold"'])
    csv_path = os.path.join(work, "held-run.csv")
    run(args, "run", scene, "--duration", str(DURATION), "--no-record", "--impacts-csv", csv_path)
    replay = subprocess.run([args.bin, "replay", mcap], capture_output=True, text=True)
    return {
        "fmu": recorded_impacts(args, mcap, work, "paper-export"),
        "run": read_impacts(csv_path, False),
        "impacts_output": int(r["impacts"][-1]),
        "max_load_output": float(r["discs[1].max_load_n"][-1]),
        "damage_output": float(r["discs[1].damage"][-1]),
        "replay_exit": replay.returncode,
        "replay": replay.stdout + replay.stderr,
        "recording": mcap,
    }


class Slave:
    """The paper case's FMU through FMPy's FMU2Slave."""

    def __init__(self, fmu, recording=None):
        self.md = read_model_description(fmu)
        self.dir = extract(fmu)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.s = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=self.dir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName="pack",
        )
        self.s.instantiate()
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        if recording:
            self.s.setString([self.vr["recording_path"]], [recording])
        self.s.exitInitializationMode()

    def get(self, name):
        return self.s.getReal([self.vr[name]])[0]

    def poll_impact(self, seen, impacts):
        """Appends the impact that closed in the last step (the FMU's last_impact outputs)
        when the count rose; returns the count. One disc: at most one closes per step."""
        count = self.s.getInteger([self.vr["impacts"]])[0]
        if count > seen:
            impacts.append(
                ["disc"] + [self.get(f"last_impact.{x}") for x in ("t_on_s", "t_peak_s",
                                                                   "t_off_s", "peak_n")]
            )
        return count

    def set(self, name, value):
        self.s.setReal([self.vr[name]], [value])

    def close(self):
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


J1 = 0.5  # kg m^2: the host's shaft, about 3 disc inertias (the coupling is felt)


def check_coupling(args):
    work = args.work
    fmu = os.path.join(work, "hu-coupling.fmu")
    p = build(args, "scenes/hu-table2.toml", fmu)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    scene = paper_scene(
        args, work, "inertial.toml",
        ['kind = "sine"', f"omega0_rad_s = {OMEGA0}", f"amplitude_rad_s = {AMPLITUDE}",
         f"frequency_hz = {FREQUENCY}"],
    )
    csv_path = os.path.join(work, "inertial-run.csv")
    run(args, "run", scene, "--duration", str(DURATION), "--no-record", "--impacts-csv", csv_path,
        "--set", 'shaft.mode="inertial"', "--set", f"shaft.inertia_kg_m2={J1}")
    out = {"run": read_impacts(csv_path, False), "master": {}}
    w = 2 * math.pi * FREQUENCY
    for scheme in ("hold", "slope", "iterated"):
        out["master"][scheme] = {}
        for h in (2e-5, 1e-5, 5e-6):
            mcap = os.path.join(work, f"coupled-{scheme}-{h:g}.mcap")
            # the iterated master redoes each step from a saved state; a recorded FMU cannot
            # roll back, so it runs unrecorded and reports the impacts as an output would
            s = Slave(fmu, recording=None if scheme == "iterated" else mcap)
            n = int(round(DURATION / h))
            omega, torque = OMEGA0, s.get("pack.shaft_torque_n_m")
            vr = s.vr["shaft.speed_rad_s"]
            seen, polled = 0, []
            for k in range(n):
                t0, t1 = k * h, (k + 1) * h
                drive = AMPLITUDE * (math.sin(w * t1) - math.sin(w * t0))
                if scheme == "hold":
                    s.set("shaft.speed_rad_s", omega)
                    s.s.doStep(currentCommunicationPoint=t0, communicationStepSize=h)
                    new_torque = s.get("pack.shaft_torque_n_m")
                else:
                    # a first-order hold: the speed's slope over the step is the shaft's
                    # acceleration at its start (eq 4)
                    slope = AMPLITUDE * w * math.cos(w * t0) + torque / J1
                    if scheme == "iterated":
                        state = s.s.getFMUState()
                    s.set("shaft.speed_rad_s", omega)
                    s.s.setRealInputDerivatives([vr], [1], [slope])
                    s.s.doStep(currentCommunicationPoint=t0, communicationStepSize=h)
                    new_torque = s.get("pack.shaft_torque_n_m")
                    if scheme == "iterated":
                        # the step again from the saved state, as a second-order hold: the
                        # acceleration's change over the step from the pack's torque at both
                        # ends (linear between them) and the drive's
                        s.s.setFMUState(state)
                        s.s.freeFMUState(state)
                        curvature = (new_torque - torque) / (h * J1) - AMPLITUDE * w * w * math.sin(
                            w * t0
                        )
                        s.set("shaft.speed_rad_s", omega)
                        s.s.setRealInputDerivatives([vr, vr], [1, 2], [slope, curvature])
                        s.s.doStep(currentCommunicationPoint=t0, communicationStepSize=h)
                        new_torque = s.get("pack.shaft_torque_n_m")
                # eq (4) over the step: the drive's impulse exactly (T_drive = J1 A w cos(w t),
                # the inertial scene's drive), the pack's torque by the trapezoid rule
                omega += drive + 0.5 * h * (torque + new_torque) / J1
                torque = new_torque
                seen = s.poll_impact(seen, polled)
            s.close()
            if scheme == "iterated":
                impacts = polled
            else:
                impacts = recorded_impacts(args, mcap, work, f"coupled-{scheme}-{h:g}")
                out.setdefault("polled_vs_recorded", []).append([polled, impacts])
            out["master"][scheme][f"{h:g}"] = impacts
    return out


def check_rollback(args):
    work, h = args.work, 1e-5
    fmu = os.path.join(work, "hu-rollback.fmu")
    p = build(args, "scenes/hu-table2.toml", fmu)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    s = Slave(fmu)
    names = ["discs[1].load_n", "pack.shaft_torque_n_m", "discs[1].speed_rad_s",
             "discs[1].max_load_n"]

    def advance(k0, k1):
        rows = []
        for k in range(k0, k1):
            s.set("shaft.speed_rad_s", float(speed(k * h)))
            s.s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            rows.append([s.get(n) for n in names] + [s.s.getInteger([s.vr["impacts"]])[0]])
        return rows

    advance(0, 2000)
    state = s.s.getFMUState()
    first = advance(2000, 3000)
    s.s.setFMUState(state)
    second = advance(2000, 3000)
    s.s.freeFMUState(state)
    s.close()
    return {"first": first, "second": second}


THERMAL_SETS = ["--set", "drive.amplitude_rad_s=0", "--set", "simulation.duration_s=0.5"]


def check_thermal(args):
    work = args.work
    fmu = os.path.join(work, "idle-thermal.fmu")
    p = build(args, "scenes/pack-8-idle-thermal.toml", fmu, *THERMAL_SETS)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    md = read_model_description(fmu)
    temps = [v for v in md.modelVariables if v.name.endswith("temperature_k")]
    names = [v.name for v in temps]
    r = fmpy.simulate_fmu(fmu, stop_time=0.5, output_interval=1e-3, output=names)
    summary = os.path.join(work, "idle-thermal.json")
    run(args, "run", "scenes/pack-8-idle-thermal.toml", *THERMAL_SETS, "--no-record",
        "--summary-json", summary)
    with open(summary) as f:
        s = json.load(f)
    return {
        "names": names,
        "units": [v.unit for v in temps],
        "causalities": [v.causality for v in temps],
        "fmu_final": [float(r[n][-1]) for n in names],
        "fmu_first": [float(r[n][0]) for n in names],
        "summary": s["thermal"],
        "problems": validate_fmu(fmu),
    }


def drive_dct(args, scene, name, inputs, outs):
    """Builds the FMU of `scene`, drives it with FMPy for 1 s at 1 ms steps (the engine's mean
    torque 250 N m and `inputs`: {input name: its schedule f(t)}, each held at the step's
    midpoint value) reading `outs`, and runs the scene with `clutchpack run`: (the FMU's input
    names, FMPy's validation problems, FMPy's result, the run's summary)."""
    work = args.work
    fmu = os.path.join(work, name + ".fmu")
    p = build(args, scene, fmu)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    md = read_model_description(fmu)
    names = [v.name for v in md.modelVariables if v.causality == "input"]
    h = 1e-3
    ts = np.arange(0.0, 1.0 + h / 2, h)
    signals = np.array(
        [(t, 250.0, *(f(t + h / 2) for f in inputs.values())) for t in ts],
        dtype=[("time", float), ("bodies.crank.drive_torque_n_m", float)]
        + [(n, float) for n in inputs],
    )
    r = fmpy.simulate_fmu(fmu, stop_time=1.0, step_size=h, input=signals, output=outs)
    summary = os.path.join(work, name + ".json")
    run(args, "run", scene, "--no-record", "--summary-json", summary)
    with open(summary) as f:
        s = json.load(f)
    return names, validate_fmu(fmu), r, s


def dct_result(names, problems, r, s):
    """What the DCT checks return: K2's heat and the vehicle's final speed through the FMU
    and in the run, and K2's lock times in the run."""
    k2s = next(c for c in s["couplings"] if c["name"] == "K2")
    vehicle = next(b for b in s["bodies"] if b["name"] == "vehicle")
    return {
        "inputs": names,
        "problems": problems,
        "fmu_heat_j": float(r["couplings.K2.heat_j"][-1]),
        "fmu_vehicle_rad_s": float(r["bodies.vehicle.speed_rad_s"][-1]),
        "run_lock_s": k2s["lock_times_s"],
        "run_heat_j": k2s["heat_j"],
        "run_vehicle_rad_s": vehicle["final_speed_rad_s"],
    }


def check_network(args):
    """The DCT upshift's FMU (a network scene): its inputs, FMPy's validation, and the shift
    driven through it: the clutches' normal forces from the scene's own schedule (K1's ramp,
    K2's table) at each 1 ms step's midpoint and the engine's mean torque, against
    `clutchpack run` of the scene."""

    def k1(t):
        return 10000.0 * min(1.0, max(0.0, 1.0 - (t - 0.2) / 0.15))

    def k2(t):
        return 10000.0 * float(np.interp(t, [0.0, 0.2, 0.35, 0.7, 0.8], [0.0, 0.0, 0.45, 0.45, 1.0]))

    outs = ["couplings.K2.mode", "couplings.K2.heat_j", "bodies.vehicle.speed_rad_s",
            "bodies.engine.speed_rad_s"]
    names, problems, r, s = drive_dct(
        args, "scenes/dct-upshift-lumped.toml", "dct-upshift-lumped",
        {"couplings.K1.normal_force_n": k1, "couplings.K2.normal_force_n": k2}, outs)
    locked = np.nonzero(r["couplings.K2.mode"] == 0)[0]
    out = dct_result(names, problems, r, s)
    out["fmu_first_locked_s"] = float(r["time"][locked[0]]) if len(locked) else None
    return out


def check_network_packs(args):
    """The FMU of the DCT upshift with both clutches resolved packs: its inputs (the engine's
    torque and both pistons' pressures), FMPy's validation, and the shift driven through it
    (the pack files' own pressure schedules at each 1 ms step's midpoint) against `clutchpack
    run` of the scene."""

    def k1(t):  # scenes/dct-k1.toml's [stack.pressure]
        return float(np.interp(t, [0.0, 0.2, 0.35], [1.05e6, 1.05e6, 0.0]))

    def k2(t):  # scenes/dct-k2.toml's
        return float(np.interp(t, [0.0, 0.2, 0.35, 0.7, 0.8], [0.0, 0.0, 0.45e6, 0.45e6, 1.05e6]))

    outs = ["couplings.K2.heat_j", "bodies.vehicle.speed_rad_s", "bodies.engine.speed_rad_s",
            "bodies.'input-2'.speed_rad_s"]
    names, problems, r, s = drive_dct(
        args, "scenes/dct-upshift.toml", "dct-upshift",
        {"couplings.K1.pressure_pa": k1, "couplings.K2.pressure_pa": k2}, outs)
    # the on-coming pack's lock: the engine's speed meets the even input shaft's
    slip = np.abs(r["bodies.engine.speed_rad_s"] - r["bodies.'input-2'.speed_rad_s"])
    after = np.nonzero((r["time"] > 0.4) & (slip < 0.5))[0]
    out = dct_result(names, problems, r, s)
    out["fmu_synchronised_s"] = float(r["time"][after[0]]) if len(after) else None
    return out


def check_network_speed(args):
    """A prescribed network body's speed through the FMU (issue 44): the model description's
    inputs (name, unit, start), a NaN refused by fmi2SetReal, the body's angle after 0.1 s
    and 0.2 s at 30 rad/s set at t = 0."""
    work = args.work
    with open(os.path.join(work, "w.csv"), "w") as f:
        f.write("time_s,speed_rad_s\n0,20\n1,40\n")
    scene = os.path.join(work, "motor.toml")
    with open(scene, "w") as f:
        f.write(args.scene_text)
    fmu = os.path.join(work, "motor.fmu")
    p = build(args, scene, fmu)
    if p.returncode != 0:
        raise SystemExit(p.stderr)
    md = read_model_description(fmu)
    units = {u.name: u for u in md.unitDefinitions}
    inputs = {
        v.name: [v.unit, float(v.start)]
        for v in md.modelVariables
        if v.causality == "input"
    }
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    fmu_slave = Slave(fmu)
    log = io.StringIO()
    # the FMU logs its reason through FMPy's logger, which prints it: kept off stdout
    with contextlib.redirect_stdout(log):
        try:
            fmu_slave.set("bodies.motor.speed_rad_s", float("nan"))
            nan_refused = False
        except Exception:  # FMPy raises on fmi2Error
            nan_refused = True
    fmu_slave.set("bodies.motor.speed_rad_s", 30.0)
    fmu_slave.s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.1)
    a1 = fmu_slave.get("bodies.motor.angle_rad")
    fmu_slave.s.doStep(currentCommunicationPoint=0.1, communicationStepSize=0.1)
    a2 = fmu_slave.get("bodies.motor.angle_rad")
    fmu_slave.close()
    return {
        "inputs": inputs,
        "units": sorted(units),
        "speed_is_output": "bodies.motor.speed_rad_s" in outputs,
        "nan_refused": nan_refused,
        "nan_log": log.getvalue(),
        "angles": [a1, a2],
        "problems": validate_fmu(fmu),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument(
        "check",
        choices=["validate", "paper", "coupling", "rollback", "thermal", "network", "network_packs",
                 "network_speed"],
    )
    ap.add_argument("--scene-text", default="")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    result = {
        "validate": check_validate,
        "paper": check_paper,
        "coupling": check_coupling,
        "rollback": check_rollback,
        "thermal": check_thermal,
        "network": check_network,
        "network_packs": check_network_packs,
        "network_speed": check_network_speed,
    }[args.check](args)
    json.dump(result, sys.stdout)


if __name__ == "__main__":
    main()
