/* sd_host.c -- host-side batch loops over a firmware module's ABI (sd_firmware.h), for the checks, the
 * tests and the benchmarks; not part of the firmware. */
#include "sd_firmware.h"

/* n poses (row-major words) -> n x 6 lengths; nsat[i] = sd_ik's saturation count of pose i (nsat may be 0) */
void sd_ik_batch(const sd_word *poses, long n, sd_word *lengths, int32_t *nsat)
{
    long i;
    for (i = 0; i < n; i++) {
        int k = sd_ik(poses + 6 * i, lengths + 6 * i);
        if (nsat) nsat[i] = k;
    }
}

