"""A clutch-to-clutch upshift closed in the loop: the 1 -> 2 shift of scenes/eight-speed.toml
(C off-going, E on-coming) with E's normal force set by a controller from E's slip every
millisecond (clutchpack.Simulation, elements by name), against the scene's own open-loop
schedule. The controller asks E's slip to fall linearly to zero over the inertia phase
(`INERTIA_S`) once C has let go; before that it holds E at its kiss point while C's force
ramps down. Prints when C let go and E locked, the heat E took and the output's speed ratio
after the shift, for both.

    python examples/python/shift_controller.py
"""

import os

import clutchpack

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "scenes", "eight-speed.toml")
STEP = 1e-3  # s: the controller's period
START, END = 1.0, 1.8  # s: the shift's start, the run's end (before the 2 -> 3 shift)
FN_MAX = 40000.0  # N: the elements' max_normal_force_n in the scene
KISS = 0.02  # E's normalized force while C lets go (the scene's fill level)
RELEASE_S = 0.15  # s: C's force from full to none
INERTIA_S = 0.2  # s: the slip's ramp to zero the controller asks for
GAIN = 4e3  # N per rad/s of slip error (proportional)
NAMES = ["couplings.C.normal_force_n", "couplings.E.normal_force_n"]


def shift(controlled: bool, engine: str = "reference") -> dict:
    """One 1 -> 2 shift; `controlled`: C and E from this controller, else the scene's
    schedule. Returns the summary's C and E entries, the instants C let go and E locked, and
    the input's and output's speeds at the end."""
    sim = clutchpack.Simulation(
        SCENE, engine=engine, drive=NAMES if controlled else [], stop_time=END
    )
    released = locked = None
    slip0 = None
    for k in range(1, round(END / STEP) + 1):
        t = k * STEP
        out = sim.outputs
        inputs = {}
        if controlled:
            # 1st gear until the shift: C closed, E open
            c_force, e_force = FN_MAX, 0.0
            if t > START:
                c_force = FN_MAX * max(0.0, 1.0 - (t - START) / RELEASE_S)
                e_force = KISS * FN_MAX
                slip = abs(out["couplings.E.slip_rad_s"])
                if released is not None:
                    # the slip's target falls linearly from its value at C's release
                    slip0 = slip if slip0 is None else slip0
                    target = slip0 * max(0.0, 1.0 - (t - released) / INERTIA_S)
                    e_force = min(FN_MAX, max(KISS * FN_MAX, KISS * FN_MAX + GAIN * (slip - target)))
                if locked is not None:
                    e_force = FN_MAX
            inputs = {NAMES[0]: c_force, NAMES[1]: e_force}
        sim.advance_to(t, **inputs)
        out = sim.outputs
        if released is None and t > START and out["couplings.C.mode"] != 0.0:
            released = t
        if locked is None and released is not None and out["couplings.E.mode"] == 0.0:
            locked = t
    summary = sim.finish()
    by_name = {c["name"]: c for c in summary["couplings"]}
    speeds = {b["name"]: b["final_speed_rad_s"] for b in summary["bodies"]}
    return {
        "released_s": released,
        "locked_s": locked,
        "E": by_name["E"],
        "C": by_name["C"],
        "input_rad_s": speeds["input"],
        "output_rad_s": speeds["output"],
    }


def main() -> None:
    for controlled in (False, True):
        r = shift(controlled)
        name = "controller" if controlled else "schedule  "
        print(
            f"{name}: C let go at {r['released_s']:.3f} s, E locked at {r['locked_s']:.3f} s "
            f"with {r['E']['heat_j']:.0f} J; output / input {r['output_rad_s'] / r['input_rad_s']:.6f} "
            f"(2nd gear: {23 / 72:.6f})"
        )


if __name__ == "__main__":
    main()
