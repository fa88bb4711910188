#include "sd_pil.h"
#include "sd_pil_config.h" /* SD_FORMAT_FINGERPRINT: written by the build from the module's recorded options */

static const uint8_t fingerprint[SD_LINK_FINGERPRINT_BYTES] = SD_FORMAT_FINGERPRINT;

static int16_t get16(const uint8_t *b) { return (int16_t)(uint16_t)(b[0] | ((uint16_t)b[1] << 8)); }

static int32_t get32(const uint8_t *b)
{
    return (int32_t)((uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24));
}

static void put16(uint8_t *b, int16_t v)
{
    b[0] = (uint8_t)((uint16_t)v & 0xFFu);
    b[1] = (uint8_t)((uint16_t)v >> 8);
}

static void put32(uint8_t *b, uint32_t v)
{
    b[0] = (uint8_t)(v & 0xFFu);
    b[1] = (uint8_t)((v >> 8) & 0xFFu);
    b[2] = (uint8_t)((v >> 16) & 0xFFu);
    b[3] = (uint8_t)(v >> 24);
}

static void put_counters(uint8_t *b, const sd_link_counters *c)
{
    put32(b, c->frames);
    put32(b + 4, c->corrupt);
    put32(b + 8, c->malformed);
    put32(b + 12, c->lost);
    put32(b + 16, c->duplicate);
    put32(b + 20, c->late);
    put32(b + 24, c->unexpected);
}

static void send(uint8_t type, uint16_t seq, const uint8_t *body, size_t n)
{
    uint8_t frame[SD_LINK_MAX_ENCODED + 1];
    size_t m = sd_link_frame(type, seq, body, n, frame);
    sd_pil_write(frame, m);
}

void sd_pil_init(sd_pil *p)
{
    sd_link_rx_init(&p->rx);
    p->seq.have_last = 0;
    p->seq.last = 0;
    p->counters.frames = p->counters.corrupt = p->counters.malformed = p->counters.lost = 0;
    p->counters.duplicate = p->counters.late = p->counters.unexpected = 0;
    p->ready = 0;
    sd_init(&p->state);
}

static void hello(sd_pil *p, uint16_t seq, const uint8_t *body)
{
    uint8_t ack[SD_HELLO_ACK_BODY];
    int i, same = body[0] == SD_LINK_VERSION;
    for (i = 0; i < SD_LINK_FINGERPRINT_BYTES; ++i) {
        same = same && body[1 + i] == fingerprint[i];
        ack[1 + i] = fingerprint[i];
    }
    ack[0] = SD_LINK_VERSION;
    ack[1 + SD_LINK_FINGERPRINT_BYTES] = (uint8_t)same;
    p->ready = same;
    p->seq.have_last = 0; /* the tick sequence starts afresh with each handshake */
    sd_init(&p->state);
    send(SD_MSG_HELLO_ACK, seq, ack, sizeof ack);
}

static void sensor(sd_pil *p, uint16_t seq, const uint8_t *body)
{
    sd_word pose[6];
    sd_count measured[6];
    int16_t feedforward[6], command[6];
    uint8_t out[SD_COMMAND_BODY];
    uint32_t start, counts;
    int i;
    if (!p->ready) {
        p->counters.unexpected++;
        return;
    }
    if (!sd_link_seq_accept(&p->seq, seq, &p->counters))
        return;
    for (i = 0; i < 6; ++i) {
        pose[i] = (sd_word)get16(body + 2 * i);
        measured[i] = get32(body + 12 + 4 * i);
        feedforward[i] = get16(body + 36 + 2 * i);
    }
    start = sd_pil_clock();
    (void)sd_tick(&p->state, pose, measured, (body[48] & 1u) ? feedforward : 0, command);
    counts = sd_pil_clock_since(start);
    out[12] = 0;
    for (i = 0; i < 6; ++i) {
        put16(out + 2 * i, command[i]);
        out[12] = (uint8_t)(out[12] | (p->state.saturated[i] ? 1u << i : 0u));
        put32(out + 41 + 4 * i, (uint32_t)(int32_t)p->state.setpoint[i]);
    }
    put_counters(out + 13, &p->counters);
    put32(out + 65, counts);
    send(SD_MSG_COMMAND, seq, out, sizeof out);
}

static void status(sd_pil *p, uint16_t seq)
{
    uint8_t out[SD_STATUS_REPLY_BODY];
    put_counters(out, &p->counters);
    put32(out + 4 * SD_LINK_COUNTERS, sd_pil_stack_used());
    send(SD_MSG_STATUS_REPLY, seq, out, sizeof out);
}

/* the controller's state as the host holds it (a closed loop starts from a held pose, not from sd_init's
 * zeros); not a tick: the sequence is unchanged. Answered with the status. */
static void set_state(sd_pil *p, uint16_t seq, const uint8_t *body)
{
    int i;
    if (!p->ready) {
        p->counters.unexpected++;
        return;
    }
    for (i = 0; i < 6; ++i) {
        p->state.integ[i] = get32(body + 4 * i);
        p->state.prev[i] = (sd_count)get32(body + 24 + 4 * i);
        p->state.dfilt[i] = get16(body + 48 + 2 * i);
        p->state.setpoint[i] = (sd_word)get32(body + 60 + 4 * i);
        p->state.vfilt[i] = get16(body + 84 + 2 * i);
    }
    status(p, seq);
}

void sd_pil_byte(sd_pil *p, uint8_t byte)
{
    size_t n = sd_link_rx_byte(&p->rx, byte, p->payload, &p->counters);
    uint16_t seq;
    if (n == 0)
        return;
    seq = (uint16_t)(p->payload[1] | ((uint16_t)p->payload[2] << 8));
    if (p->payload[0] == SD_MSG_HELLO && n == 3 + SD_HELLO_BODY)
        hello(p, seq, p->payload + 3);
    else if (p->payload[0] == SD_MSG_SENSOR && n == 3 + SD_SENSOR_BODY)
        sensor(p, seq, p->payload + 3);
    else if (p->payload[0] == SD_MSG_STATUS && n == 3 + SD_STATUS_BODY)
        status(p, seq);
    else if (p->payload[0] == SD_MSG_SET_STATE && n == 3 + SD_SET_STATE_BODY)
        set_state(p, seq, p->payload + 3);
    else {
        p->counters.frames--; /* a good CRC but not a message this end takes */
        p->counters.malformed++;
    }
}
