/* sd_loop.h -- the closed loop's DSP side in one call per stop (``firmware.loop_kernel``, driven by
 * ``drake.tick_loop.TickLoop``): read the plant state in Drake's memory, the sensor, the law's tick (the float
 * law, or the compiled firmware's ``sd_host_tick``), the output release, the actuators (saturation and lag:
 * ``control.actuation``) with their force written in Drake's memory, the logs appended. Not part of the
 * firmware. The block between the CDEF markers is also the cffi declaration (read by ``loop_kernel``): plain
 * C, no macros. */
#ifndef SD_LOOP_H
#define SD_LOOP_H

#include <stdint.h>

/* CDEF BEGIN */
typedef struct {
    const double *x;          /* the plant state in Drake's context (positions, then velocities) */
    double *input;            /* the plant's actuation input in Drake's context (6, N): the actuators' force */
    const double *times;      /* per stop: time (s) */
    const int32_t *tick;      /* per stop: tick index, -1 none */
    const int8_t *release;    /* per stop: a separate output release */
    const int8_t *log;        /* per stop: a log row */
    const int8_t *step;       /* per stop: a plant step (the actuators' lag steps there) */
    long n_stops;
    long n_ticks;             /* rows of the tables below */
    const double *setpoint;   /* float law: (n_ticks, 6) set-points (m) */
    const void *pose_words;   /* fixed law: (n_ticks, 6) pose words (sd_word) */
    const double *ff;         /* (n_ticks, 6) feed-forward (N), or 0 */
    int ideal_sensor;         /* the reading is x[pos] */
    const int64_t *pos;       /* (6,) indices of the legs' lengths in x */
    const int64_t *vel;       /* (6,) indices of their rates in x */
    const double *offset;     /* (6,) m */
    const double *noise;      /* (n_noise, 6) m */
    const double *jitter;     /* (n_noise,) s */
    long n_noise;
    double noise_period;      /* s */
    int fixed;                /* 1: the firmware's sd_host_tick, 0: the float law */
    int latency_none;         /* a tick's result is released at the tick */
    int at_tick;              /* else the previous tick's result is released at the next tick */
    double kp, kd_T, kv_T, ki_T, alpha_d, alpha_ff, lim, res;   /* float law (SI) */
    const double *length_offset;                              /* float law: (6,) m */
    void *fw_state;           /* fixed law: the firmware's sd_state */
    double range, lsb;        /* fixed law: command range (N), set-point LSB (m) */
    double held[12];          /* released command (N) and set-point (m) */
    double memory[42];        /* pending command and set-point (12), the law's PID state (30) */
    double status[10];        /* control.STATUS */
    double *held_log;         /* (n_rows, 12) */
    double *status_log;       /* (n_rows, 10) */
    double *x_log;            /* (n_rows, nx) */
    double *force_log;        /* (n_rows, 6): the actuators' force */
    int has_lag;              /* the actuators: saturation at +-max_force, then (has_lag) a first-order lag */
    double max_force, lag_a, lag_b;   /* N; F <- lag_a F + lag_b u at each plant step */
    double lag_force[6];      /* the lag's state F (N) */
    long nx;
    long row;
    long n_rows;
    double error_lengths[6];  /* the reading a failed tick could not convert */
} sd_loop;
int sd_loop_log(sd_loop *L, long i);
int sd_loop_update(sd_loop *L, long i);
int sd_loop_stop(sd_loop *L, long i);
/* CDEF END */

#endif
