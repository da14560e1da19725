#!/usr/bin/env python3
"""The FMU misused as a careless or hostile host would (issue 36), each case in a child
process of its own so that a crash of the host shows as a signal, never as a lost test:

    "$py" tests/python/fmu_misuse.py --bin CLUTCHPACK --root REPO --work DIR

builds the FMUs it needs with `clutchpack fmu`, runs every case as
`fmu_misuse.py --case NAME ...` and prints one JSON object: per case its exit code (negative:
the signal that killed it), the status its last FMI call answered ("error" when FMPy raised
on fmi2Error, "ok" otherwise), and what the FMU logged. The assertions are in
tests/hardening.rs.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys

from ctypes import c_void_p

import numpy as np

LOG = []


def slave(fmu, name="host", unzipped=None):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
    from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE
    from fmpy import calloc, free

    md = read_model_description(fmu)
    d = unzipped or extract(fmu)
    s = FMU2Slave(guid=md.guid, unzipDirectory=d,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    s.vr = {v.name: v.valueReference for v in md.modelVariables}
    s.dir = d

    def logger(env, inst, status, category, message):
        LOG.append(message.decode("utf-8", "replace"))

    cb = fmi2CallbackFunctions()
    s._logger = fmi2CallbackLoggerTYPE(logger)  # kept alive as long as the slave
    cb.logger = s._logger
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    from ctypes import byref
    from fmpy.logging import addLoggerProxy

    # the FMU logs "%s" with the message as its argument: the proxy formats it
    addLoggerProxy(byref(cb))
    s._cb = cb
    return s, cb


def start(fmu, recording=None, stop=None, name="host", unzipped=None):
    s, cb = slave(fmu, name, unzipped)
    s.instantiate(callbacks=cb)
    s.setupExperiment(startTime=0.0, stopTime=stop)
    s.enterInitializationMode()
    if recording is not None:
        s.setString([s.vr["recording_path"]], [recording])
    s.exitInitializationMode()
    return s


def case_free_twice(a):
    s = start(a.paper)
    s.fmi2FreeInstance(s.component)
    s.fmi2FreeInstance(s.component)
    # and a call on the freed instance
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-4)


def case_set_freed_state(a):
    s = start(a.paper)
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-4)
    st = s.getFMUState()
    raw = c_void_p(st.value)  # FMPy nulls its own copy when it frees
    s.freeFMUState(st)
    s.setFMUState(raw)


def case_free_state_twice(a):
    s = start(a.paper)
    st = s.getFMUState()
    raw = c_void_p(st.value)
    s.freeFMUState(st)
    s.freeFMUState(raw)


def case_state_of_another_instance(a):
    # A runs unrecorded and saves; B records: A's state would rewind B's recording
    from fmpy import extract

    # one binary loaded once, two instances of it
    d = extract(a.paper)
    x = start(a.paper, name="a", unzipped=d)
    x.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    st = x.getFMUState()
    y = start(a.paper, recording=os.path.join(a.work, "b.mcap"), name="b", unzipped=d)
    y.doStep(currentCommunicationPoint=0.0, communicationStepSize=2e-3)
    y.setFMUState(st)


def case_state_of_another_scene(a):
    x = start(a.paper, name="paper")
    st = x.getFMUState()
    y = start(a.brake, name="brake")
    y.setFMUState(st)


def case_recording_path_is_a_folder(a):
    start(a.paper, recording=a.work)


def case_recording_path_is_dev_null(a):
    start(a.paper, recording="/dev/null")


def case_recording_path_is_the_fmus_scene(a):
    s, cb = slave(a.paper)
    s.instantiate(callbacks=cb)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setString([s.vr["recording_path"]], [os.path.join(s.dir, "resources", "scene.json")])
    s.exitInitializationMode()


def case_recording_path_is_the_fmus_binary(a):
    """A recording over the FMU's own shared library (in the folder the host extracted) would
    replace it: refused, and a second instance from the same folder still loads and runs."""
    s, cb = slave(a.paper)
    binaries = os.path.join(s.dir, "binaries")
    so = [os.path.join(r, f) for r, _, fs in os.walk(binaries) for f in fs]
    assert so, f"no binary under {binaries}"
    size = os.path.getsize(so[0])
    s.instantiate(callbacks=cb)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setString([s.vr["recording_path"]], [so[0]])
    try:
        s.exitInitializationMode()
    finally:
        # the library is intact and a second instance from the same folder runs
        assert os.path.getsize(so[0]) == size, "the FMU's binary was replaced"
        t = start(a.paper, name="second", unzipped=s.dir)
        t.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        LOG.append("second instance ran")


def case_network_drive_torque_out_of_bounds(a):
    """A network's drive torque beyond the scene key's bound, set before the run starts
    (it made the first 1 ms step run for minutes)."""
    s, cb = slave(a.network)
    s.instantiate(callbacks=cb)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal([s.vr["bodies.crank.drive_torque_n_m"]], [1e30])


def case_network_clutch_force_out_of_bounds(a):
    s = start(a.network)
    s.setReal([s.vr["couplings.K2.normal_force_n"]], [1e30])


def case_shaft_speed_out_of_bounds(a):
    s = start(a.paper)
    s.setReal([s.vr["shaft.speed_rad_s"]], [1e9])


def case_slope_out_of_bounds(a):
    s = start(a.paper)
    vr = s.vr["shaft.speed_rad_s"]
    s.setReal([vr], [200.0])
    s.setRealInputDerivatives([vr], [1], [1e12])
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)


def case_pressure_out_of_bounds(a):
    s = start(a.engagement)
    s.setReal([s.vr["piston.pressure_pa"]], [1e15])


def case_do_step_at_nan(a):
    s = start(a.paper)
    s.doStep(currentCommunicationPoint=float("nan"), communicationStepSize=1e-3)


def case_edited_scene(a):
    from fmpy import extract
    d = extract(a.paper)
    p = os.path.join(d, "resources", "scene.json")
    scene = json.load(open(p))
    scene["simulation"]["record_rate_hz"] = 1e300
    json.dump(scene, open(p, "w"), indent=2)
    shutil.make_archive(os.path.join(a.work, "edited"), "zip", d)
    os.replace(os.path.join(a.work, "edited.zip"), os.path.join(a.work, "edited.fmu"))
    start(os.path.join(a.work, "edited.fmu"))


def provenance(mcap_path):
    """The scene file named, the attachments and `clutchpack.params` of a recording."""
    from mcap.reader import make_reader

    with open(mcap_path, "rb") as f:
        r = make_reader(f)
        meta = {m.name: dict(m.metadata) for m in r.iter_metadata()}
        attachments = [a.name for a in r.iter_attachments()]
    return {"scene_file": meta.get("clutchpack.run", {}).get("scene_file"),
            "attachments": attachments, "params": meta.get("clutchpack.params", {})}


def ending(a, name, drive):
    """Runs the engagement FMU recorded (the pressure ramp 0 -> 1 MPa from 40 to 90 ms) and
    ends it by `drive`; returns the recorded impacts' largest |peak| (N), what `clutchpack
    replay` says of the file, and its provenance."""
    import fmpy

    work = os.path.join(a.work, name)
    os.makedirs(work, exist_ok=True)
    rec = os.path.join(work, "run.mcap")
    drive(rec)
    out = os.path.join(work, "export")
    p = subprocess.run([a.bin, "export", rec, "--csv", out], capture_output=True, text=True)
    peaks = []
    if p.returncode == 0:
        import csv

        with open(os.path.join(out, "impacts.csv")) as f:
            peaks = [abs(float(r["peak_n"])) for r in csv.DictReader(f)]
    replay = subprocess.run([a.bin, "replay", rec], capture_output=True, text=True)
    return {"export_exit": p.returncode, "impacts": len(peaks),
            "max_abs_peak_n": max(peaks, default=0.0), "replay": replay.stdout[:300],
            **provenance(rec)}


def pressure(t):
    return float(np.clip((t - 0.04) / 0.05, 0.0, 1.0) * 1e6)


def ends(a):
    """Every way a co-simulated run can end, recorded: FMPy's simulate_fmu (its last step
    lands a rounding error past the stop time), a host that steps exactly to the stop time
    and terminates, one that terminates early without a stop time, and one that frees the
    instance without terminating."""
    import fmpy

    def simulate(rec):
        t = np.array([0.0, 0.04, 0.09, 0.12])
        u = np.array(list(zip(t, [pressure(x) for x in t])),
                     dtype=[("time", np.float64), ("piston.pressure_pa", np.float64)])
        fmpy.simulate_fmu(a.engagement, stop_time=0.12, output_interval=1e-4, input=u,
                          start_values={"recording_path": rec}, validate=False)

    def stepped(stop, n, terminate):
        def go(rec):
            s = start(a.engagement, recording=rec, stop=stop)
            h = 1e-4
            for k in range(n):
                s.setReal([s.vr["piston.pressure_pa"]], [pressure(k * h)])
                s.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            if terminate:
                s.terminate()
            s.fmi2FreeInstance(s.component)
        return go

    return {
        "simulate_fmu": ending(a, "simulate_fmu", simulate),
        "exact_stop": ending(a, "exact_stop", stepped(0.12, 1200, True)),
        "early_terminate": ending(a, "early_terminate", stepped(None, 700, True)),
        "free_without_terminate": ending(a, "free_without_terminate", stepped(None, 700, False)),
    }


CASES = {k[5:]: v for k, v in dict(globals()).items() if k.startswith("case_")}


def child(a):
    status = "ok"
    why = ""
    try:
        CASES[a.case](a)
    except Exception as e:  # FMPy raises on fmi2Error and on a null instance
        status, why = "error", str(e)
    print(json.dumps({"status": status, "exception": why, "log": LOG}))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--case")
    ap.add_argument("--paper")
    ap.add_argument("--brake")
    ap.add_argument("--engagement")
    ap.add_argument("--network")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    if a.case == "ENDS":
        print(json.dumps(ends(a)))
        return
    if a.case:
        child(a)
        return
    fmus = {}
    for key, scene in [("paper", "hu-table2"), ("brake", "pack-8-brake"),
                       ("engagement", "pack-6-engagement"),
                       ("network", "dct-upshift-lumped")]:
        out = os.path.join(a.work, scene + ".fmu")
        p = subprocess.run([a.bin, "fmu", os.path.join(a.root, "scenes", scene + ".toml"),
                            "--out", out], capture_output=True, text=True)
        if p.returncode != 0:
            raise SystemExit(f"clutchpack fmu {scene}: {p.stderr}")
        fmus[key] = out
    result = {}
    for name in CASES:
        work = os.path.join(a.work, name)
        os.makedirs(work, exist_ok=True)
        p = subprocess.run(
            [sys.executable, __file__, "--bin", a.bin, "--root", a.root, "--work", work,
             "--case", name, "--paper", fmus["paper"], "--brake", fmus["brake"],
             "--engagement", fmus["engagement"], "--network", fmus["network"]],
            capture_output=True, text=True, timeout=300,
        )
        last = p.stdout.strip().splitlines()[-1] if p.stdout.strip() else "{}"
        try:
            r = json.loads(last)
        except ValueError:
            r = {"stdout": p.stdout[-2000:]}
        r["exit"] = p.returncode
        r["stderr"] = p.stderr[-2000:]
        result[name] = r
    p = subprocess.run(
        [sys.executable, __file__, "--bin", a.bin, "--root", a.root, "--work",
         os.path.join(a.work, "ends"), "--case", "ENDS", "--paper", fmus["paper"],
         "--brake", fmus["brake"], "--engagement", fmus["engagement"]],
        capture_output=True, text=True, timeout=600,
    )
    if p.returncode != 0:
        raise SystemExit(f"the endings: exit {p.returncode}: {p.stderr[-3000:]}")
    result["ends"] = json.loads(p.stdout.strip().splitlines()[-1])
    result["dev_null_is_a_character_device"] = os.path.exists("/dev/null") and \
        __import__("stat").S_ISCHR(os.stat("/dev/null").st_mode)
    json.dump(result, sys.stdout)


if __name__ == "__main__":
    main()
