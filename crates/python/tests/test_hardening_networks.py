"""Hardening, round 3 (issue 48) through the wheel: the network Simulation keeps the bounds
and the output policy the pack Simulation keeps. Run by tests/python_package.rs with the
other pytest files (the working folder is the repository root)."""

import shutil
from pathlib import Path

import pytest

import clutchpack


def test_network_simulation_inputs_are_checked_against_their_scene_keys_bounds():
    """Item 7: a network Simulation's inputs were checked for finiteness only (a drive torque
    of 1e30 N m, a pressure of -1e30 Pa were taken). Each raises ValueError naming the input
    and the scene key's bound; the run is unchanged and goes on with a good value."""
    names = ["bodies.crank.drive_torque_n_m", "couplings.K2.normal_force_n"]
    sim = clutchpack.Simulation("scenes/dct-upshift-lumped.toml", drive=names)
    with pytest.raises(ValueError, match=r"bodies.crank.drive_torque_n_m = 1e30 N m.*bodies\[\]\.drive\.value_n_m"):
        sim.advance_to(0.001, **{names[0]: 1e30})
    with pytest.raises(ValueError, match=r"couplings.K2.normal_force_n = -1e30 N"):
        sim.advance_to(0.001, **{names[1]: -1e30})
    assert sim.time == 0.0
    sim.advance_to(0.001, **{names[0]: 250.0, names[1]: 0.0})
    assert abs(sim.time - 0.001) < 1e-12
    sim.finish()
    packs = clutchpack.Simulation("scenes/dct-upshift.toml", drive=["couplings.K2.pressure_pa"])
    with pytest.raises(ValueError, match=r"couplings.K2.pressure_pa = 1e30 Pa"):
        packs.advance_to(0.001, **{"couplings.K2.pressure_pa": 1e30})
    packs.finish()


def test_network_record_over_a_pack_file_is_refused(tmp_path):
    """Item 6: `record=` over a file the scene reads (a network's pack file, a force table)
    replaced it. ValueError naming the argument, and the file is as it was."""
    for f in ["dct-upshift.toml", "dct-k1.toml", "dct-k2.toml", "dct-upshift-lumped.toml",
              "dct-upshift-k2.csv"]:
        shutil.copy(f"scenes/{f}", tmp_path / f)
    for scene, target in [("dct-upshift.toml", "dct-k2.toml"),
                          ("dct-upshift-lumped.toml", "dct-upshift-k2.csv")]:
        before = (tmp_path / target).read_bytes()
        with pytest.raises(ValueError, match="is an input of this run"):
            clutchpack.Simulation(str(tmp_path / scene), record=tmp_path / target)
        with pytest.raises(ValueError, match="is an input of this run"):
            clutchpack.run(str(tmp_path / scene), record=tmp_path / target)
        assert (tmp_path / target).read_bytes() == before


# `cases::prescribed_clutch` as a scene file, shared with the Rust tests (run from the
# repository root, as every test here)
MOTOR = Path("tests/data/motor-clutch.toml").read_text()


@pytest.mark.parametrize("engine", ["reference", "multibody"])
def test_network_prescribed_speed_is_an_input_and_bad_speeds_are_refused(tmp_path, engine):
    """Issue 44: a prescribed network body's speed is an input by the one-pack scene's name
    (``bodies.motor.speed_rad_s``, rad/s), no output of that name beside it; a free body's speed is
    no input, and a speed that is not finite or beyond the scene key's 1e5 rad/s raises
    ValueError naming it, the run unchanged; a value set holds the speed from the body's
    angle then (the angle continuous, the speed the value; the angles to 1e-9 rad, measured
    within rounding, 1e-15)."""
    (tmp_path / "w.csv").write_text("time_s,speed_rad_s\n0,20\n1,40\n")
    (tmp_path / "motor.toml").write_text(MOTOR)
    name = "bodies.motor.speed_rad_s"
    with pytest.raises(ValueError, match=r"bodies.load.speed_rad_s.*not an input"):
        clutchpack.Simulation(str(tmp_path / "motor.toml"), engine=engine,
                              drive=["bodies.load.speed_rad_s"])
    sim = clutchpack.Simulation(str(tmp_path / "motor.toml"), engine=engine, drive=[name])
    assert sim.inputs == [name]
    assert sim.variables[name][:2] == ("input", "rad/s")
    with pytest.raises(ValueError, match=name):
        sim.advance_to(0.1, **{name: float("nan")})
    with pytest.raises(ValueError, match=r"bodies\[\]\.speed\.omega0_rad_s"):
        sim.advance_to(0.1, **{name: 1e6})
    assert sim.time == 0.0
    assert name not in sim.outputs
    sim.advance_to(0.1)
    angle = sim.outputs["bodies.motor.angle_rad"]
    # held at its start value, 20 rad/s, until set
    assert abs(angle - 20.0 * 0.1) < 1e-9
    # set where the run stands (0.1 s to rounding), held to 0.2 s from the angle there
    sim.advance_to(0.2, **{name: 30.0})
    assert abs(sim.outputs["bodies.motor.angle_rad"] - (angle + 30.0 * 0.1)) < 1e-9
    sim.finish()
