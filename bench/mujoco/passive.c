/* The open brake pack's passive torques for MuJoCo (bench/mujoco/brake.py builds and loads
 * this file; see docs/performance.md). One hinge per stack body, in stack order plate, disc,
 * plate, ..., plate. Each body is splined to its carrier: a disc to the prescribed shaft, a
 * plate to the fixed housing. The tooth law is the dry law of docs/MODEL.md sections 1 and 2,
 * the open gaps' drag that of section 5.
 *
 *   phi   = theta_carrier - theta_body              relative angle, rad
 *   delta = (|phi| - g0) Rb                         penetration on the line of action, m
 *   v_n   = sign(phi) (w_carrier - w_body) Rb       closing speed, m/s
 *   |F|   = max(0, (1 + p v_n) H delta^1.5)         per-tooth load, N (delta > 0)
 *   T     = sign(phi) n |F| Rb                      torque on the body, N m
 *   T_gap = -c (w_b - w_b+1) on b, +c (...) on b+1  c = pi eta (Ro^4 - Ri^4) / (2 h), N m s
 *
 * The shaft's angle is the closed form of the sine drive w = w0 + A sin(2 pi f t), theta(0) = 0.
 */
#include <math.h>
#include <mujoco/mujoco.h>

#define MAX_BODIES 257

typedef struct {
    double teeth, base_radius_m, half_play_rad;
} Spline;

static Spline disc_spline, plate_spline;
static double hertz, loss_s_m;      /* H = 4/3 E sqrt(r), N/m^1.5; p, s/m */
static double w0, amp, freq;        /* the shaft's drive: rad/s, rad/s, Hz */
static double gap_c;                /* the open gap's drag coefficient, N m s/rad */
static int bodies;                  /* 2 N + 1 */
static double peak_n[MAX_BODIES];   /* each body's largest per-tooth load, N */

static double tooth_torque(const Spline *s, double phi, double dphi, double *load) {
    double a = fabs(phi) - s->half_play_rad;
    if (a <= 0.0) return 0.0;
    double sign = phi > 0.0 ? 1.0 : -1.0;
    double delta = a * s->base_radius_m;
    double vn = sign * dphi * s->base_radius_m;
    double f = (1.0 + loss_s_m * vn) * hertz * delta * sqrt(delta);
    if (f <= 0.0) return 0.0;
    *load = f;
    return sign * s->teeth * f * s->base_radius_m;
}

static void passive(const mjModel *m, mjData *d) {
    (void)m;
    double k = 2.0 * M_PI * freq;
    double shaft_angle = w0 * d->time + amp / k * (1.0 - cos(k * d->time));
    double shaft_speed = w0 + amp * sin(k * d->time);
    for (int b = 0; b < bodies; b++) {
        int disc = b % 2 == 1;
        double load = 0.0;
        double phi = (disc ? shaft_angle : 0.0) - d->qpos[b];
        double dphi = (disc ? shaft_speed : 0.0) - d->qvel[b];
        d->qfrc_passive[b] += tooth_torque(disc ? &disc_spline : &plate_spline, phi, dphi, &load);
        if (load > peak_n[b]) peak_n[b] = load;
    }
    for (int b = 0; b + 1 < bodies; b++) {
        double t = -gap_c * (d->qvel[b] - d->qvel[b + 1]);
        d->qfrc_passive[b] += t;
        d->qfrc_passive[b + 1] -= t;
    }
}

/* The pack's parameters (SI), then the callback installed into MuJoCo. 0, or -1 for too many
 * bodies. */
int brake_install(int discs, double d_teeth, double d_rb, double d_g0, double p_teeth,
                  double p_rb, double p_g0, double h, double p, double omega0,
                  double amplitude, double frequency, double c_gap) {
    if (2 * discs + 1 > MAX_BODIES) return -1;
    bodies = 2 * discs + 1;
    disc_spline = (Spline){d_teeth, d_rb, d_g0};
    plate_spline = (Spline){p_teeth, p_rb, p_g0};
    hertz = h; loss_s_m = p; w0 = omega0; amp = amplitude; freq = frequency; gap_c = c_gap;
    for (int b = 0; b < MAX_BODIES; b++) peak_n[b] = 0.0;
    mjcb_passive = passive;
    return 0;
}

double brake_peak_n(int body) { return body >= 0 && body < bodies ? peak_n[body] : NAN; }
