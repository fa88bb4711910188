/* The PIL link's framing, target side (also compiled for the host): C99, no libc beyond <stdint.h>/<stddef.h>.
 *
 * A frame on the wire is COBS(payload) followed by one 0x00 delimiter; the payload is
 *     type (u8) | seq (u16, little-endian) | body | CRC-16/CCITT-FALSE of type..body (u16, big-endian).
 * Multi-byte body fields are little-endian. The message types and bodies are in docs/pil-link.md and in
 * stewart_drake/firmware/link.py, the host side. */
#ifndef SD_LINK_H
#define SD_LINK_H

#include <stddef.h>
#include <stdint.h>

#define SD_LINK_VERSION 2
#define SD_LINK_MAX_PAYLOAD 128 /* bytes: type + seq + body + crc */
#define SD_LINK_MAX_ENCODED (SD_LINK_MAX_PAYLOAD + SD_LINK_MAX_PAYLOAD / 254 + 1)
#define SD_LINK_FINGERPRINT_BYTES 8

enum { SD_MSG_HELLO = 1, SD_MSG_HELLO_ACK = 2, SD_MSG_SENSOR = 3, SD_MSG_COMMAND = 4, SD_MSG_STATUS = 5, SD_MSG_STATUS_REPLY = 6,
       SD_MSG_SET_STATE = 7 };

/* The receiver's counts; a frame counted in any of the last six is never acted on. */
typedef struct {
    uint32_t frames;     /* frames decoded with a good CRC */
    uint32_t corrupt;    /* CRC mismatch */
    uint32_t malformed;  /* bad COBS, too short or too long, unknown type or wrong body size */
    uint32_t lost;       /* sequence numbers skipped */
    uint32_t duplicate;  /* the sequence number just acted on, again */
    uint32_t late;       /* a sequence number older than the last acted on */
    uint32_t unexpected; /* a tick before a successful handshake */
} sd_link_counters;

#define SD_LINK_COUNTERS 7

typedef struct {
    uint8_t buf[SD_LINK_MAX_ENCODED];
    size_t len;
    int overflow;
} sd_link_rx;

typedef struct {
    int have_last;
    uint16_t last;
} sd_link_seq;

uint16_t sd_crc16(const uint8_t *data, size_t n);
size_t sd_cobs_encode(const uint8_t *in, size_t n, uint8_t *out);
/* the decoded length, or -1 for an invalid encoding or one longer than cap */
long sd_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap);
/* the frame (encoded payload and delimiter) in out (SD_LINK_MAX_ENCODED + 1 bytes); returns its length */
size_t sd_link_frame(uint8_t type, uint16_t seq, const uint8_t *body, size_t n, uint8_t *out);
void sd_link_rx_init(sd_link_rx *rx);
/* one received byte: returns the payload length (type..body, CRC checked and removed) into payload
 * (SD_LINK_MAX_PAYLOAD bytes) when it ends a good frame, else 0; counts corrupt and malformed frames */
size_t sd_link_rx_byte(sd_link_rx *rx, uint8_t byte, uint8_t *payload, sd_link_counters *c);
/* 1 when seq is new (act on it), 0 for a duplicate or late one; counts lost, duplicate and late */
int sd_link_seq_accept(sd_link_seq *s, uint16_t seq, sd_link_counters *c);

#endif
