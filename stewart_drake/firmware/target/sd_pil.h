/* The processor-in-the-loop program: the link's messages around the generated sd_init/sd_tick.
 * I/O free: sd_pil_byte takes each received byte and replies through sd_pil_write, which the board's
 * runtime (sd_uart_cmsdk.c, or the host's stdio in a test) defines. */
#ifndef SD_PIL_H
#define SD_PIL_H

#include "sd_firmware.h"
#include "sd_link.h"

#define SD_SENSOR_BODY 49  /* pose i16[6], measured i32[6], feedforward i16[6], flags u8 (bit 0: feed-forward) */
#define SD_COMMAND_BODY 69 /* command i16[6], saturated legs u8 (bit i: leg i + 1), counters u32[7],
                            set-point words i32[6], sd_tick's clock counts u32 (0xFFFFFFFF: not measured) */
#define SD_HELLO_BODY 9    /* version u8, format fingerprint u8[8] */
#define SD_HELLO_ACK_BODY 10 /* version u8, format fingerprint u8[8], accepted u8 */
#define SD_STATUS_BODY 0
#define SD_STATUS_REPLY_BODY 32 /* counters u32[7], stack high-water mark u32 (bytes; 0xFFFFFFFF: not measured) */
#define SD_SET_STATE_BODY 96 /* integ i32[6], prev i32[6], dfilt i16[6], setpoint i32[6], vfilt i16[6] */

typedef struct {
    sd_link_rx rx;
    sd_link_seq seq;
    sd_link_counters counters;
    sd_state state;
    int ready; /* a handshake with our version and fingerprint was acknowledged */
    uint8_t payload[SD_LINK_MAX_PAYLOAD];
} sd_pil;

void sd_pil_init(sd_pil *p);
void sd_pil_byte(sd_pil *p, uint8_t byte);
/* defined by the runtime: send n bytes */
void sd_pil_write(const uint8_t *data, size_t n);
/* defined by the runtime: the most stack used since reset, bytes (0xFFFFFFFF where it is not measured) */
uint32_t sd_pil_stack_used(void);
/* defined by the runtime: a free-running clock, and the counts since a reading of it (0xFFFFFFFF where the
 * runtime has no clock) */
uint32_t sd_pil_clock(void);
uint32_t sd_pil_clock_since(uint32_t start);

#endif
