#include "sd_link.h"

uint16_t sd_crc16(const uint8_t *data, size_t n)
{
    uint16_t crc = 0xFFFFu; /* CRC-16/CCITT-FALSE: polynomial 0x1021, init 0xFFFF, no reflection */
    size_t i;
    int b;
    for (i = 0; i < n; ++i) {
        crc ^= (uint16_t)((uint16_t)data[i] << 8);
        for (b = 0; b < 8; ++b) {
            uint16_t shifted = (uint16_t)(crc << 1);
            crc = (crc & 0x8000u) ? (uint16_t)(shifted ^ 0x1021u) : shifted;
        }
    }
    return crc;
}

size_t sd_cobs_encode(const uint8_t *in, size_t n, uint8_t *out)
{
    size_t code_at = 0, o = 1, i;
    uint8_t code = 1;
    for (i = 0; i < n; ++i) {
        if (in[i] == 0) {
            out[code_at] = code;
            code_at = o++;
            code = 1;
        } else {
            out[o++] = in[i];
            if (++code == 0xFF) {
                out[code_at] = code;
                code_at = o++;
                code = 1;
            }
        }
    }
    out[code_at] = code;
    return o;
}

long sd_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap)
{
    size_t i = 0, o = 0, k;
    while (i < n) {
        uint8_t code = in[i++];
        if (code == 0 || i + (size_t)code - 1 > n)
            return -1;
        for (k = 1; k < code; ++k) {
            if (in[i] == 0 || o >= cap)
                return -1;
            out[o++] = in[i++];
        }
        if (code != 0xFF && i < n) {
            if (o >= cap)
                return -1;
            out[o++] = 0;
        }
    }
    return (long)o;
}

size_t sd_link_frame(uint8_t type, uint16_t seq, const uint8_t *body, size_t n, uint8_t *out)
{
    uint8_t p[SD_LINK_MAX_PAYLOAD];
    size_t len = 0, i, m;
    uint16_t crc;
    if (n + 5 > SD_LINK_MAX_PAYLOAD)
        return 0;
    p[len++] = type;
    p[len++] = (uint8_t)(seq & 0xFFu);
    p[len++] = (uint8_t)(seq >> 8);
    for (i = 0; i < n; ++i)
        p[len++] = body[i];
    crc = sd_crc16(p, len);
    p[len++] = (uint8_t)(crc >> 8);
    p[len++] = (uint8_t)(crc & 0xFFu);
    m = sd_cobs_encode(p, len, out);
    out[m++] = 0;
    return m;
}

void sd_link_rx_init(sd_link_rx *rx)
{
    rx->len = 0;
    rx->overflow = 0;
}

size_t sd_link_rx_byte(sd_link_rx *rx, uint8_t byte, uint8_t *payload, sd_link_counters *c)
{
    long n;
    uint16_t crc;
    if (byte != 0) {
        if (rx->len < sizeof rx->buf)
            rx->buf[rx->len++] = byte;
        else
            rx->overflow = 1;
        return 0;
    }
    if (rx->len == 0 && !rx->overflow)
        return 0; /* an empty frame: delimiters in a row (a resynchronisation) */
    n = rx->overflow ? -1 : sd_cobs_decode(rx->buf, rx->len, payload, SD_LINK_MAX_PAYLOAD);
    sd_link_rx_init(rx);
    if (n < 5) {
        c->malformed++;
        return 0;
    }
    crc = (uint16_t)(((uint16_t)payload[n - 2] << 8) | payload[n - 1]);
    if (sd_crc16(payload, (size_t)n - 2) != crc) {
        c->corrupt++;
        return 0;
    }
    c->frames++;
    return (size_t)n - 2;
}

int sd_link_seq_accept(sd_link_seq *s, uint16_t seq, sd_link_counters *c)
{
    uint16_t d;
    if (!s->have_last) {
        s->have_last = 1;
        s->last = seq;
        return 1;
    }
    d = (uint16_t)(seq - s->last);
    if (d == 0) {
        c->duplicate++;
        return 0;
    }
    if (d >= 0x8000u) {
        c->late++;
        return 0;
    }
    c->lost += (uint32_t)(d - 1u);
    s->last = seq;
    return 1;
}
