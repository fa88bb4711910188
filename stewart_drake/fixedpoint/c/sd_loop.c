/* sd_loop.c -- the closed loop's DSP side per stop (see sd_loop.h). The arithmetic is that of the numpy
 * reference, operation for operation (compiled with -ffp-contract=off): ``control.laws.FloatLaw.step``,
 * ``control.dsp_state.tick`` / ``release`` and ``drake.tick_loop.SensorReading``; the fixed-point law is the
 * firmware's own sd_tick through sd_host_tick (as ``firmware.sil.CFixedPointLaw``). With SD_LOOP_FIXED the
 * file is linked with a firmware module; without, the fixed-point law is absent. */
#include <math.h>
#include <string.h>

#include "sd_loop.h"

#ifdef SD_LOOP_FIXED
#include "sd_firmware.h"
int sd_host_tick(sd_state *s, const sd_word pose[6], const double L[6], double res, const double *ff, double range,
                 double lsb, double state[30], double out[18]);
#endif

/* np.minimum(np.maximum(v, -lim), lim), NaN passing through as in numpy (and Drake's Saturation of finite values) */
static double clip(double v, double lim)
{
    v = v < -lim ? -lim : v;
    return v > lim ? lim : v;
}

/* control.laws.FloatLaw.step on pid[30] with the set-points sp, the readings meas and ff (or 0): the command
 * and set-point into out[12], the new PID state into pid_new[30], saturation flags into sat[6] */
static void float_step(const sd_loop *L, const double *pid, const double *sp, const double *meas, const double *ff,
                       double *out, double *pid_new, double *sat)
{
    int i;
    for (i = 0; i < 6; i++) {
        double m = rint(meas[i] / L->res) * L->res + L->length_offset[i];
        double integ = pid[i], prev = pid[6 + i], dfilt = pid[12 + i], sp_prev = pid[18 + i], vfilt = pid[24 + i];
        double e = sp[i] - m, u_raw, u;
        int grow;
        dfilt = dfilt + L->alpha_d * ((m - prev) - dfilt);
        vfilt = vfilt + L->alpha_ff * ((sp[i] - sp_prev) - vfilt);
        u_raw = L->kp * e + integ - L->kd_T * dfilt + L->kv_T * vfilt;
        if (ff) u_raw = u_raw + ff[i];
        u = clip(u_raw, L->lim);
        sat[i] = u_raw != u ? 1.0 : 0.0;
        grow = !((u_raw > L->lim && e > 0) || (u_raw < -L->lim && e < 0));
        if (grow) integ = clip(integ + L->ki_T * e, L->lim);
        out[i] = u;
        out[6 + i] = sp[i];
        pid_new[i] = integ;
        pid_new[6 + i] = m;
        pid_new[12 + i] = dfilt;
        pid_new[18 + i] = sp[i];
        pid_new[24 + i] = vfilt;
    }
}

/* drake.tick_loop.SensorReading (or the ideal sensor) at time t */
static void sensor(const sd_loop *L, double t, double *out)
{
    int i;
    if (L->ideal_sensor) {
        for (i = 0; i < 6; i++) out[i] = L->x[L->pos[i]];
        return;
    }
    {
        long k = (long)rint(t / L->noise_period);
        const double *noise;
        double jitter;
        if (k > L->n_noise - 1) k = L->n_noise - 1;
        noise = L->noise + 6 * k;
        jitter = L->jitter[k];
        for (i = 0; i < 6; i++) out[i] = L->x[L->pos[i]] + L->offset[i] + noise[i] - jitter * L->x[L->vel[i]];
    }
}

/* control.dsp_state.tick at tick k, time t; -1 if the firmware could not take the reading */
static int tick(sd_loop *L, long k, double t)
{
    double meas[6], next[42], sat[6];
    const double *ff = L->ff ? L->ff + 6 * k : 0;
    int i, any = 0;
    if (k < 0 || k >= L->n_ticks) return -2;
    sensor(L, t, meas);
    if (L->fixed) {
#ifdef SD_LOOP_FIXED
        double out[18];
        memcpy(next + 12, L->memory + 12, 30 * sizeof(double));
        if (sd_host_tick((sd_state *)L->fw_state, (const sd_word *)L->pose_words + 6 * k, meas, L->res, ff, L->range,
                         L->lsb, next + 12, out) < 0) {
            memcpy(L->error_lengths, meas, sizeof meas);
            return -1;
        }
        memcpy(next, out, 12 * sizeof(double));
        memcpy(sat, out + 12, sizeof sat);
#else
        return -3;
#endif
    } else {
        float_step(L, L->memory + 12, L->setpoint + 6 * k, meas, ff, next, next + 12, sat);
    }
    L->status[0] += 1;
    L->status[1] = t;
    for (i = 0; i < 6; i++) {
        any |= sat[i] != 0;
        L->status[4 + i] += sat[i];
    }
    L->status[3] += any ? 1.0 : 0.0;
    if (L->latency_none) {
        memcpy(L->held, next, 12 * sizeof(double));
        L->status[2] = t;
    } else if (L->at_tick && L->status[0] > 1) {
        memcpy(L->held, L->memory, 12 * sizeof(double));  /* the previous tick's result */
        L->status[2] = t;
    }
    memcpy(L->memory, next, sizeof next);
    return 0;
}

/* The log row of stop i (i = -1: t = 0), if it logs there: the held values and status before its updates,
 * the plant state and the actuators' force (what the plant integrates with). Returns 0. */
int sd_loop_log(sd_loop *L, long i)
{
    if (i >= 0 && !L->log[i]) return 0;
    if (L->row >= L->n_rows) return -2;
    memcpy(L->held_log + 12 * L->row, L->held, 12 * sizeof(double));
    memcpy(L->status_log + 10 * L->row, L->status, 10 * sizeof(double));
    memcpy(L->x_log + L->nx * L->row, L->x, L->nx * sizeof(double));
    memcpy(L->force_log + 6 * L->row, L->input, 6 * sizeof(double));
    L->row++;
    return 0;
}

/* The updates at stop i (i = -1: the tick at t = 0): the tick or the separate release, then the actuators
 * (control.actuation.Actuation): at a plant step their lag takes the command held before the
 * controller's update there, F <- a F + b sat(u) (simultaneous discrete updates read the old state); without
 * a lag the force is the command just held, saturated. Returns 1 if the force changed (the caller notifies
 * Drake), 0 if not, < 0 on an error (-1: a reading the firmware cannot take, see error_lengths). */
int sd_loop_update(sd_loop *L, long i)
{
    double before[12], force[6];
    long k = i < 0 ? 0 : L->tick[i];
    double t = i < 0 ? 0.0 : L->times[i];
    int j, step = i < 0 ? 1 : L->step[i];
    memcpy(before, L->held, sizeof before);
    if (k >= 0) {
        int r = tick(L, k, t);
        if (r < 0) return r;
    } else if (L->release[i] && L->status[0] >= 1) {
        memcpy(L->held, L->memory, 12 * sizeof(double));
        L->status[2] = t;
    }
    if (L->has_lag) {
        if (!step) return 0;
        for (j = 0; j < 6; j++) L->lag_force[j] = L->lag_a * L->lag_force[j] + L->lag_b * clip(before[j], L->max_force);
        memcpy(force, L->lag_force, sizeof force);
    } else {
        for (j = 0; j < 6; j++) force[j] = clip(L->held[j], L->max_force);
    }
    if (memcmp(L->input, force, sizeof force) == 0) return 0;
    memcpy(L->input, force, sizeof force);
    return 1;
}

/* sd_loop_log and sd_loop_update of stop i: one call per stop of a continuous plant */
int sd_loop_stop(sd_loop *L, long i)
{
    int r = sd_loop_log(L, i);
    return r < 0 ? r : sd_loop_update(L, i);
}
