/* Classical washout as a streaming step: the law of control/cueing/classical.py, one sample at a time from a
   state, for a real-time loop (classical_kernel.py loads it; see there for the layout of coef and state).

   Eight IIR filters in transposed direct form II (scipy.signal.lfilter's form), each of order <= 3 padded with
   zero coefficients: 0-2 the translational channels (x, y, z), 3-4 the tilt low-passes (x, y), 5-7 the
   rotational channels (roll, pitch, yaw). */
#include <math.h>
#include <stdint.h>

enum { FILTERS = 8, NC = 7, NZ = 3 };
enum { SXY = FILTERS * NC, SZ, SROT, GRAV, TILT_MAX, TILT_STEP, HOME };
enum { PREV = FILTERS * NZ, STARTED = PREV + 2 };

static double iir(const double *c, double *z, double x) {
    double y = c[0] * x + z[0];
    z[0] = c[1] * x + z[1] - c[4] * y;
    z[1] = c[2] * x + z[2] - c[5] * y;
    z[2] = c[3] * x - c[6] * y;
    return y;
}

static double clamp(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* One sample: u = (fx, fy, fz, wx, wy, wz) in, pose (6) out. */
static void step(const double *coef, double *state, const double *u, double *pose) {
    const double sxy = coef[SXY], sz = coef[SZ], g = coef[GRAV];
    const double acc[3] = {sxy * u[0], sxy * u[1], sz * u[2] - sz * g};
    for (int i = 0; i < 3; i++) pose[i] = coef[HOME + i] + iir(coef + i * NC, state + i * NZ, acc[i]);
    double fx = iir(coef + 3 * NC, state + 3 * NZ, sxy * u[0]);
    double fy = iir(coef + 4 * NC, state + 4 * NZ, sxy * u[1]);
    double pitch = asin(clamp(-fx / g, -1.0, 1.0));
    double roll = asin(clamp(fy / (g * cos(pitch)), -1.0, 1.0));
    double target[2] = {clamp(roll, -coef[TILT_MAX], coef[TILT_MAX]), clamp(pitch, -coef[TILT_MAX], coef[TILT_MAX])};
    for (int i = 0; i < 2; i++) {
        if (state[STARTED] == 0.0) state[PREV + i] = target[i];
        else state[PREV + i] += clamp(target[i] - state[PREV + i], -coef[TILT_STEP], coef[TILT_STEP]);
    }
    state[STARTED] = 1.0;
    for (int i = 0; i < 3; i++) {
        double rot = iir(coef + (5 + i) * NC, state + (5 + i) * NZ, coef[SROT] * u[3 + i]);
        double angle = coef[HOME + 3 + i];
        if (i < 2) angle += state[PREV + i]; /* home + tilt, then + rotation: classical.py's order of sums */
        pose[3 + i] = angle + rot;
    }
}

/* n samples u (n, 6) -> pose (n, 6), carrying state from sample to sample (and from call to call). */
void sd_washout(int64_t n, const double *coef, double *state, const double *u, double *pose) {
    for (int64_t k = 0; k < n; k++) step(coef, state, u + 6 * k, pose + 6 * k);
}
