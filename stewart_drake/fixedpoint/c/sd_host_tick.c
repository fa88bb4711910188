/* sd_host_tick.c -- the host's side of one controller tick for the controller in the loop (not part of
 * the firmware): conversions in C, so that one call per tick does everything. */
#include <math.h>

#include "sd_firmware.h"

/* One controller tick with the host's side of the interface done in C, for the controller in the loop:
 * L (m) -> sensor counts rint(L / res) (ties to even, as numpy's round); ff (N, may be 0) -> Q15 words
 * sat16(rint(ff / range * 32768)); state[30] (the LeafSystem's vector: integ, prev, dfilt, setpoint,
 * vfilt) in and out; out[18] = command (N), set-point (m), saturated flags. Returns -1 (nothing done) if
 * a measurement does not fit the 32-bit counts, else sd_tick's return value. */
int sd_host_tick(sd_state *s, const sd_word pose[6], const double L[6], double res, const double *ff, double range,
                 double lsb, double state[30], double out[18])
{
    sd_count m[6];
    int16_t ffw[6], cmd[6];
    int i, r;
    for (i = 0; i < 6; i++) {
        double c = rint(L[i] / res);
        if (!(c >= -2147483647.0 && c <= 2147483647.0)) return -1;
        m[i] = (sd_count)c;
        if (ff) {
            double w = rint(ff[i] / range * 32768.0);
            ffw[i] = (int16_t)(w > 32767.0 ? 32767 : w < -32768.0 ? -32768 : (int)w);
        }
        s->integ[i] = (int32_t)state[i];
        s->prev[i] = (sd_count)state[6 + i];
        s->dfilt[i] = (int16_t)state[12 + i];
        s->setpoint[i] = (sd_word)state[18 + i];
        s->vfilt[i] = (int16_t)state[24 + i];
    }
    r = sd_tick(s, pose, m, ff ? ffw : 0, cmd);
    for (i = 0; i < 6; i++) {
        out[i] = (double)cmd[i] / 32768.0 * range;
        out[6 + i] = (double)s->setpoint[i] * lsb;
        out[12 + i] = s->saturated[i];
        state[i] = s->integ[i];
        state[6 + i] = s->prev[i];
        state[12 + i] = s->dfilt[i];
        state[18 + i] = s->setpoint[i];
        state[24 + i] = s->vfilt[i];
    }
    return r;
}
