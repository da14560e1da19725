#!/usr/bin/env python3
"""The open brake pack in MuJoCo, timed beside clutchpack on the same pack (docs/performance.md).

N friction discs splined to a prescribed shaft and N + 1 separator plates splined to the fixed
housing, stacked plate, disc, plate, ..., plate, with the open gaps' oil drag between
neighbours; 0.1 s simulated. The pack is `clutchpack_model::cases::staggered_brake(N)`: the
discs of scenes/staggered-16-disc.toml (dry law, 154 teeth, started across +-0.8 of the free
play at rest relative to the shaft), the plates of scenes/pack-8-brake.toml (132 teeth at
0.305 m, 30 deg, 0.5 mm) with the discs' dry law, the piston released.

MuJoCo gets one hinge per body and the tooth law and the gaps' drag as a passive force in C
(bench/mujoco/passive.c, compiled here against the headers and library of the `mujoco` wheel),
integrated by explicit Euler at 1 us (the step at which one impact's peak is within 0.05 % of
the closed form of docs/MODEL.md section 4). clutchpack runs the same pack from a scene file
this script writes.

    python3 bench/mujoco/brake.py                 # 16 discs, 3 rounds, both timed in turn
    python3 bench/mujoco/brake.py --discs 8 --rounds 5 --engine multibody
    python3 bench/mujoco/brake.py --mujoco-only   # without clutchpack

Everything it makes goes under target/mujoco/ (or $CARGO_TARGET_DIR/mujoco): a virtual
environment with the pinned `mujoco` of bench/mujoco/requirements.txt from PyPI, the compiled
callback, the model and the scene. clutchpack is target/release/clutchpack (build it first:
`cargo build --release`) unless --clutchpack names another binary. Needs python3 (with venv)
and a C compiler (cc).
"""
import argparse
import hashlib
import math
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
WORK = os.path.join(TARGET, "mujoco")
VENV = os.path.join(WORK, "venv")
REQUIREMENTS = os.path.join(HERE, "requirements.txt")

DURATION_S = 0.1
STEP_S = 1e-6
# The discs (scenes/staggered-16-disc.toml): J, kg m^2; teeth; pitch radius, m; pressure
# angle, deg; backlash, m.
DISC = dict(inertia=0.194306, teeth=154, radius=0.231, alpha_deg=20.0, backlash=0.75e-3)
# The plates (scenes/pack-8-brake.toml's plate_defaults).
PLATE = dict(inertia=0.1382, teeth=132, radius=0.305, alpha_deg=30.0, backlash=0.5e-3)
# The dry law (docs/MODEL.md section 2): E, Pa; r, m; p, s/m.
MODULUS_PA, CURVATURE_M, LOSS_S_M = 210e9, 5e-3, 0.5
# The drive (Hu et al. eq 3): w = w0 + A sin(2 pi f t).
OMEGA0, AMPLITUDE, FREQUENCY = 100.0, 4.378, 104.0
# The open gaps (docs/MODEL.md section 5): eta, Pa s; h, m; faces Ri .. Ro, m.
GAP_ETA, GAP_H, FACE_RI, FACE_RO = 0.01, 1e-3, 0.235, 0.290


def ensure_venv():
    """Re-runs this script inside target/mujoco/venv, made (and `mujoco` installed) first."""
    python = os.path.join(VENV, "bin", "python")
    if os.path.realpath(sys.prefix) == os.path.realpath(VENV):
        return
    stamp = os.path.join(VENV, ".requirements.sha256")
    want = hashlib.sha256(open(REQUIREMENTS, "rb").read()).hexdigest()
    if not (os.path.exists(python) and os.path.exists(stamp) and open(stamp).read() == want):
        print(f"brake.py: making {VENV} (pip install -r {REQUIREMENTS})", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", "--clear", VENV], check=True)
        subprocess.run([python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                        "-r", REQUIREMENTS], check=True)
        open(stamp, "w").write(want)
    os.execv(python, [python, os.path.abspath(__file__)] + sys.argv[1:])


def half_play_rad(s):
    """g0 = d / (2 R), rad (docs/MODEL.md section 1)."""
    return s["backlash"] / (2.0 * s["radius"])


def base_radius_m(s):
    """Rb = R cos(alpha), m."""
    return s["radius"] * math.cos(math.radians(s["alpha_deg"]))


def stagger_rad(i, n):
    """Disc i's phi(0) = theta_shaft - theta_disc: -0.8 g0 (2 (i + 1/2) / n - 1)
    (`clutchpack_model::cases::staggered_rel_angle_rad`)."""
    return -0.8 * half_play_rad(DISC) * (2.0 * (i + 0.5) / n - 1.0)


def gap_drag_n_m_s():
    """The open gap's Couette drag coefficient pi eta (Ro^4 - Ri^4) / (2 h), N m s/rad."""
    return math.pi * GAP_ETA * (FACE_RO**4 - FACE_RI**4) / (2.0 * GAP_H)


def mjcf(n):
    """The MuJoCo model: 2 n + 1 bodies, one hinge about z each, in stack order; no gravity,
    no contacts (the teeth and the gaps are the passive callback's)."""
    bodies = []
    for b in range(2 * n + 1):
        s = DISC if b % 2 else PLATE
        j = s["inertia"]
        bodies.append(
            f'<body name="b{b}" pos="0 0 {0.004 * b:.3f}">'
            f'<inertial pos="0 0 0" mass="1" diaginertia="{j} {j} {j}"/>'
            f'<joint name="j{b}" type="hinge" axis="0 0 1" damping="0"/></body>')
    return (f'<mujoco model="brake-{n}">'
            f'<option timestep="{STEP_S}" integrator="Euler" gravity="0 0 0">'
            f'<flag contact="disable" constraint="disable"/></option>'
            f'<worldbody>{"".join(bodies)}</worldbody></mujoco>')


def scene(n):
    """The same pack as a clutchpack scene (`cases::staggered_brake(n)`)."""
    discs = "".join(f'[[discs]]\nname = "disc-{i + 1}"\ninitial_rel_angle_rad = {stagger_rad(i, n)!r}\n'
                    for i in range(n))
    plates = "".join(f'[[plates]]\nname = "plate-{j + 1}"\n' for j in range(n + 1))

    def body(section, s):
        return (f"[{section}]\ninertia_kg_m2 = {s['inertia']}\ndrag_n_m_s_rad = 0.0\n"
                f"[{section}.spline]\nteeth = {s['teeth']}\npitch_radius_m = {s['radius']}\n"
                f"pressure_angle_deg = {s['alpha_deg']}\nbacklash_m = {s['backlash']}\n"
                f'[{section}.contact]\nlaw = "dry"\nmodulus_pa = {MODULUS_PA}\n'
                f"curvature_radius_m = {CURVATURE_M}\nloss_coefficient_s_m = {LOSS_S_M}\n")

    return (f'# Written by bench/mujoco/brake.py: the open brake pack of {n} discs it times in MuJoCo.\n'
            f'name = "brake-{n}"\n'
            f'description = "{n} staggered dry-law discs on a prescribed shaft, {n + 1} plates on the housing, open gaps"\n'
            f"[simulation]\nduration_s = {DURATION_S}\nrecord_rate_hz = 10000.0\nmax_step_s = 1e-4\n"
            f'[shaft]\nmode = "prescribed"\n'
            f'[drive]\nkind = "sine"\nomega0_rad_s = {OMEGA0}\namplitude_rad_s = {AMPLITUDE}\n'
            f"frequency_hz = {FREQUENCY}\n"
            + body("defaults", DISC) + body("plate_defaults", PLATE) + discs + plates +
            f"[stack]\nface_inner_radius_m = {FACE_RI}\nface_outer_radius_m = {FACE_RO}\n"
            f"piston_area_m2 = 0.05\nreturn_spring_n = 2000.0\nspline_friction_coefficient = 0.0\n"
            f"[stack.friction]\nstatic_mu = 0.10\nkinetic_mu = 0.13\nstribeck_speed_m_s = 0.5\n"
            f'[stack.pressure]\nkind = "constant"\npressure_pa = 0.0\n'
            f"[stack.open_gap]\nviscosity_pa_s = {GAP_ETA}\ngap_m = {GAP_H}\n")


def build_callback(mujoco):
    """Compiles passive.c against the wheel's headers and library; returns its ctypes handle."""
    import ctypes
    pkg = os.path.dirname(mujoco.__file__)
    lib = next(f for f in sorted(os.listdir(pkg)) if f.startswith("libmujoco.so"))
    out = os.path.join(WORK, "passive.so")
    src = os.path.join(HERE, "passive.c")
    if not os.path.exists(out) or os.path.getmtime(out) < os.path.getmtime(src):
        subprocess.run([os.environ.get("CC", "cc"), "-O2", "-shared", "-fPIC", "-o", out, src,
                        "-I", os.path.join(pkg, "include"), "-L", pkg, f"-l:{lib}",
                        f"-Wl,-rpath,{pkg}", "-lm"], check=True)
    cb = ctypes.CDLL(out)
    cb.brake_install.restype = ctypes.c_int
    cb.brake_install.argtypes = [ctypes.c_int] + [ctypes.c_double] * 12
    cb.brake_peak_n.restype = ctypes.c_double
    cb.brake_peak_n.argtypes = [ctypes.c_int]
    return cb


def run_mujoco(mujoco, cb, n):
    """One run of DURATION_S: returns (wall time of the stepping, s; each body's peak per-tooth
    load, N)."""
    model = mujoco.MjModel.from_xml_string(mjcf(n))
    for b in range(2 * n + 1):
        assert model.jnt_qposadr[b] == b and model.jnt_dofadr[b] == b
    data = mujoco.MjData(model)
    hertz = 4.0 / 3.0 * MODULUS_PA * math.sqrt(CURVATURE_M)
    rc = cb.brake_install(n, DISC["teeth"], base_radius_m(DISC), half_play_rad(DISC),
                          PLATE["teeth"], base_radius_m(PLATE), half_play_rad(PLATE),
                          hertz, LOSS_S_M, OMEGA0, AMPLITUDE, FREQUENCY, gap_drag_n_m_s())
    if rc != 0:
        sys.exit(f"brake.py: {n} discs are more than passive.c holds")
    for i in range(n):
        b = 2 * i + 1
        data.qpos[b] = -stagger_rad(i, n)  # theta_disc = theta_shaft(0) - phi(0)
        data.qvel[b] = OMEGA0
    mujoco.mj_forward(model, data)
    steps = round(DURATION_S / STEP_S)
    t0 = time.perf_counter()
    mujoco.mj_step(model, data, nstep=steps)
    wall = time.perf_counter() - t0
    if any(w.number for w in data.warning):
        sys.exit("brake.py: MuJoCo warned during the run (an unstable step?)")
    if abs(data.time - DURATION_S) > 0.5 * STEP_S:
        sys.exit(f"brake.py: MuJoCo stopped at {data.time} s")
    return wall, [cb.brake_peak_n(b) for b in range(2 * n + 1)]


def run_clutchpack(binary, scene_path, engine):
    """One whole clutchpack process on the scene (`engine`: None for the automatic choice):
    its wall time, s."""
    cmd = [binary, "run", scene_path, "--no-record"] + (["--engine", engine] if engine else [])
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--discs", type=int, default=16, help="N, the discs (N + 1 plates)")
    ap.add_argument("--rounds", type=int, default=3, help="timed runs of each, in turn")
    ap.add_argument("--mujoco-only", action="store_true", help="time MuJoCo alone")
    ap.add_argument("--engine", choices=["reference", "multibody"],
                    help="clutchpack's engine (default: its automatic choice, the reference)")
    ap.add_argument("--clutchpack", default=os.path.join(TARGET, "release", "clutchpack"),
                    help="the clutchpack binary (default target/release/clutchpack)")
    args = ap.parse_args()
    if args.discs < 1 or args.rounds < 1:
        sys.exit("brake.py: --discs and --rounds must be at least 1")
    if not args.mujoco_only and not os.access(args.clutchpack, os.X_OK):
        sys.exit(f"brake.py: {args.clutchpack} not found: `cargo build --release` first, "
                 "or --clutchpack PATH, or --mujoco-only")
    os.makedirs(WORK, exist_ok=True)
    ensure_venv()
    import mujoco
    cb = build_callback(mujoco)
    n = args.discs
    scene_path = os.path.join(WORK, f"brake-{n}.toml")
    open(scene_path, "w").write(scene(n))
    print(f"open brake pack, {n} discs + {n + 1} plates, {DURATION_S} s simulated; "
          f"MuJoCo {mujoco.__version__} (explicit Euler, {STEP_S:g} s), stepping only; "
          f"clutchpack whole process ({scene_path}, engine {args.engine or 'automatic'})")
    mj, cp, peaks = [], [], None
    for r in range(args.rounds):
        wall, peaks = run_mujoco(mujoco, cb, n)
        mj.append(wall)
        line = f"round {r + 1}: MuJoCo {wall:.3f} s"
        if not args.mujoco_only:
            cp.append(run_clutchpack(args.clutchpack, scene_path, args.engine))
            line += f", clutchpack {cp[-1]:.3f} s"
        print(line, flush=True)
    plates = peaks[0::2]
    print(f"MuJoCo's largest per-tooth loads: end plates {plates[0]:.1f} / {plates[-1]:.1f} N, "
          f"inner plates up to {max(plates[1:-1], default=float('nan')):.1f} N, "
          f"discs up to {max(peaks[1::2]):.1f} N")
    line = f"median: MuJoCo {statistics.median(mj):.3f} s"
    if cp:
        ratio = statistics.median(mj) / statistics.median(cp)
        line += f", clutchpack {statistics.median(cp):.3f} s ({ratio:.1f}x)"
    print(line)


if __name__ == "__main__":
    main()
