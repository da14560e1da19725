"""A controller in the loop: the 6-disc clutch of scenes/pack-6-engagement.toml engaged by a
pressure that Python sets every millisecond (clutchpack.Simulation), so that the drum speeds
up at a chosen rate, against the scene's own pressure ramp. Prints when the drum reaches the
shaft's speed, the faces' heat and the largest tooth load of both engagements: the shift's
trade-off between heat and tooth loads, with the pack's rattle in it.

    python examples/python/cosim_engagement.py
"""

import os

import clutchpack

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "scenes", "pack-6-engagement.toml")
STEP = 1e-3  # s: the controller's period
DURATION = 0.3  # s
TARGET = 2500.0  # rad/s^2: the drum's acceleration the controller asks for
GAIN = 100.0  # Pa per (rad/s^2) per step: the integral gain
OMEGA0 = 200.0  # rad/s: the shaft's mean speed (the scene's drive)


def engage(controlled: bool) -> dict:
    """One engagement on the reference engine; `controlled`: the pressure from the
    controller, else the scene's ramp. Returns the run's summary and when the drum came
    within 1 % of the shaft's mean speed."""
    sim = clutchpack.Simulation(
        SCENE,
        engine="reference",
        drive=["piston.pressure_pa"] if controlled else [],
        stop_time=DURATION,
    )
    pressure, last_speed, synced = 0.0, 0.0, None
    for k in range(1, round(DURATION / STEP) + 1):
        inputs = {"piston.pressure_pa": pressure} if controlled else {}
        sim.advance_to(k * STEP, **inputs)
        out = sim.outputs
        speed = out["drum.speed_rad_s"]
        if controlled:
            # integral action on the drum's acceleration over the last period
            accel = (speed - last_speed) / STEP
            pressure = max(0.0, pressure + GAIN * (TARGET - accel))
        last_speed = speed
        if synced is None and speed > 0.99 * OMEGA0:
            synced = sim.time
    return {"summary": sim.finish(), "synced": synced}


def main() -> None:
    for name, run in [("scene's ramp", engage(False)), ("controller", engage(True))]:
        s = run["summary"]
        heat = sum(i["dissipated_j"] for i in s["interfaces"])
        worst = max(s["discs"], key=lambda d: max(d["max_positive_n"], -d["max_negative_n"]))
        peak = max(worst["max_positive_n"], -worst["max_negative_n"])
        synced = "never" if run["synced"] is None else f"{run['synced']:.3f} s"
        print(
            f"{name:>13}: drum at the shaft's speed from {synced}, faces' heat {heat:.0f} J, "
            f"hardest-hit body {worst['name']} {peak:.0f} N per tooth"
        )


if __name__ == "__main__":
    main()
