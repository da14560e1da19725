#!/usr/bin/env python3
"""The FMU in a real-time loop: a wall-clock-synchronised master, as a hardware-in-the-loop
host runs it, advancing a pack's FMU in fixed frames with FMPy and printing the frames' wall
time distribution (docs/cosimulation.md, "Real time").

Frame k starts at k frame lengths of wall time after the first (the master sleeps until
then); in it the master sets the shaft's speed (the scene's sine drive, Hu et al. eq 3),
calls doStep over the frame and reads the outputs, as a rig's task does. A frame that takes
longer than the budget (0.8 of the frame) is an overrun; a frame that starts late (the one
before ran over) is counted too. The FMU's model description says what it honours in real
time (`canHandleVariableCommunicationStepSize`, `canGetAndSetFMUstate`, and clutchpack's
`RealTime` vendor annotation), printed first.

    clutchpack fmu scenes/pack-8-brake.toml --out pack-8-brake.fmu
    python examples/python/fmu_realtime.py pack-8-brake.fmu --duration 2
    python examples/python/fmu_realtime.py pack-8-brake.fmu --json   # the figures as JSON

Needs FMPy (`pip install fmpy`). Pin the master to a core (`taskset -c 1`) and give it a
real-time policy (`chrt -f 50`) as a rig does: on a shared machine the scheduler's noise,
not the FMU, makes the worst frames otherwise.
"""

import argparse
import json
import math
import shutil
import statistics
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

# The scenes' drive (Hu et al. eq 3, Table 2): w = w0 + A sin(2 pi f t), rad/s.
OMEGA0, AMPLITUDE, FREQUENCY = 200.0, 4.378, 104.0


def quantile(sorted_values, q):
    """The `q` quantile (nearest rank) of sorted values."""
    i = min(len(sorted_values), max(1, math.ceil(q * len(sorted_values)))) - 1
    return sorted_values[i]


def real_time_facts(unzipped):
    """What the model description says of real time: the co-simulation flags and the
    `RealTime` element of clutchpack's vendor annotation."""
    root = ET.parse(f"{unzipped}/modelDescription.xml").getroot()
    cs = root.find("CoSimulation").attrib
    facts = {k: cs[k] for k in ("canHandleVariableCommunicationStepSize",
                                "canGetAndSetFMUstate", "canRunAsynchronuously")}
    tool = root.find("VendorAnnotations/Tool[@name='clutchpack']/RealTime")
    if tool is not None:
        facts.update(tool.attrib)
    return facts


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("fmu", help="a pack's FMU (clutchpack fmu SCENE --out FILE)")
    ap.add_argument("--frame", type=float, default=1e-3, help="the frame, s")
    ap.add_argument("--duration", type=float, default=1.0, help="simulated (and wall) time, s")
    ap.add_argument("--budget", type=float, default=0.8,
                    help="a frame's budget as a fraction of the frame")
    ap.add_argument("--json", action="store_true", help="the figures as JSON on stdout")
    a = ap.parse_args()
    if not (a.frame > 0 and a.duration >= a.frame and a.budget > 0):
        sys.exit("fmu_realtime.py: expected --frame > 0, --duration >= --frame, --budget > 0")

    md = read_model_description(a.fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    if "shaft.speed_rad_s" not in vr:
        sys.exit(f"fmu_realtime.py: {a.fmu} has no input shaft.speed_rad_s (a pack on a "
                 "prescribed shaft is expected)")
    outputs = [vr[n] for n in ("pack.shaft_torque_n_m", "discs[1].load_n") if n in vr]
    unzipped = extract(a.fmu, unzipdir=tempfile.mkdtemp(prefix="fmu-realtime-"))
    facts = real_time_facts(unzipped)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="rt")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0, stopTime=a.duration)
    if "duration_limit_s" in vr:
        # the run may go past the scene's own duration (a step past the limit fails)
        slave.setReal([vr["duration_limit_s"]], [a.duration])
    slave.enterInitializationMode()
    slave.exitInitializationMode()

    n = max(1, round(a.duration / a.frame))
    wall, cpu, late = [], [], 0
    start = time.perf_counter()
    for k in range(n):
        due = start + k * a.frame
        now = time.perf_counter()
        if due > now:
            time.sleep(due - now)
        elif now - due > a.frame:
            late += 1
        w0, c0 = time.perf_counter(), time.thread_time()
        t = k * a.frame
        slave.setReal([vr["shaft.speed_rad_s"]],
                      [OMEGA0 + AMPLITUDE * math.sin(2 * math.pi * FREQUENCY * t)])
        slave.doStep(currentCommunicationPoint=t, communicationStepSize=a.frame)
        slave.getReal(outputs)
        wall.append(time.perf_counter() - w0)
        cpu.append(time.thread_time() - c0)
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

    budget = a.budget * a.frame
    ws, cs = sorted(wall), sorted(cpu)
    figures = {
        "frames": n,
        "frame_s": a.frame,
        "budget_s": budget,
        "median_s": statistics.median(ws),
        "p99_s": quantile(ws, 0.99),
        "p999_s": quantile(ws, 0.999),
        "max_s": ws[-1],
        "overruns": sum(x > budget for x in ws),
        "cpu_max_s": cs[-1],
        "cpu_overruns": sum(x > budget for x in cs),
        "late_frames": late,
        "real_time_factor": sum(ws) / (n * a.frame),
        "model_description": facts,
    }
    if a.json:
        print(json.dumps(figures))
        return
    print("model description: " + ", ".join(f"{k}={v}" for k, v in facts.items()))
    print(f"{n} frames of {a.frame * 1e3:g} ms through the FMU (budget {budget * 1e6:.0f} us):")
    print(f"  frame wall time: median {figures['median_s'] * 1e6:.0f} us, p99 "
          f"{figures['p99_s'] * 1e6:.0f} us, p99.9 {figures['p999_s'] * 1e6:.0f} us, max "
          f"{figures['max_s'] * 1e6:.0f} us; {figures['overruns']} overrun(s), {late} late frame(s)")
    print(f"  frame CPU time: max {figures['cpu_max_s'] * 1e6:.0f} us; "
          f"{figures['cpu_overruns']} over the budget")
    print(f"  real-time factor {figures['real_time_factor']:.3f} (the frames' time over the "
          "simulated time)")


if __name__ == "__main__":
    main()
