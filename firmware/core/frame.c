/* CRC, frame encoding, little-endian fields and the receiver of
 * docs/serial-protocol.md ("Frame", "CRC", "Receiving"). */
#include "evdev.h"

#include <string.h>

uint16_t evdev_crc16(const uint8_t *p, size_t n) {
    uint16_t crc = 0xFFFFu;
    while (n--) {
        crc ^= (uint16_t)((uint16_t)(*p++) << 8);
        for (int k = 0; k < 8; k++) {
            crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
        }
    }
    return crc;
}

void evdev_put_u16(uint8_t *p, uint16_t v) {
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

void evdev_put_u32(uint8_t *p, uint32_t v) {
    for (int k = 0; k < 4; k++) {
        p[k] = (uint8_t)((v >> (8 * k)) & 0xFFu);
    }
}

void evdev_put_f32(uint8_t *p, float v) {
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    evdev_put_u32(p, bits);
}

uint16_t evdev_get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }

uint32_t evdev_get_u32(const uint8_t *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

float evdev_get_f32(const uint8_t *p) {
    uint32_t bits = evdev_get_u32(p);
    float v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

size_t evdev_encode(uint8_t *out, uint8_t type, uint16_t seq, const uint8_t *payload, uint8_t len) {
    if (len > EVDEV_MAX_PAYLOAD) {
        return 0;
    }
    out[0] = EVDEV_SYNC0;
    out[1] = EVDEV_SYNC1;
    out[2] = len;
    out[3] = type;
    evdev_put_u16(out + 4, seq);
    if (len) {
        memcpy(out + 6, payload, len);
    }
    evdev_put_u16(out + 6 + len, evdev_crc16(out + 2, (size_t)len + 4u));
    return (size_t)len + EVDEV_OVERHEAD;
}

int evdev_payload_len(uint8_t type) {
    switch (type) {
    case EVDEV_HELLO: return 8;
    case EVDEV_ACTUATION: return 2;
    case EVDEV_TOUCH: return 13;
    case EVDEV_FORCE: return 4;
    case EVDEV_HEARTBEAT: return 6;
    case EVDEV_FAULT: return 2;
    default: return -1;
    }
}

void evdev_decoder_init(evdev_decoder *d) { memset(d, 0, sizeof *d); }

/* Drops the first k buffered bytes. */
static void skip(evdev_decoder *d, uint8_t k, int garbage) {
    memmove(d->buf, d->buf + k, (size_t)(d->n - k));
    d->n = (uint8_t)(d->n - k);
    if (garbage) {
        d->stats.garbage += k;
    }
}

/* Applies the rules to the buffered bytes until more are needed. */
static void drain(evdev_decoder *d, evdev_on_frame on_frame, void *ctx) {
    for (;;) {
        if (d->n == 0) {
            return;
        }
        if (d->buf[0] != EVDEV_SYNC0) { /* rule 1 */
            skip(d, 1, 1);
            continue;
        }
        if (d->n < 2) {
            return;
        }
        if (d->buf[1] != EVDEV_SYNC1) {
            skip(d, 1, 1);
            continue;
        }
        if (d->n < 3) {
            return;
        }
        uint8_t len = d->buf[2];
        if (len > EVDEV_MAX_PAYLOAD) { /* rule 2 */
            d->stats.bad_length++;
            skip(d, 1, 1);
            continue;
        }
        uint8_t total = (uint8_t)(len + EVDEV_OVERHEAD);
        if (d->n < total) {
            return;
        }
        uint16_t want = evdev_get_u16(d->buf + 6 + len);
        if (evdev_crc16(d->buf + 2, (size_t)len + 4u) == want) { /* rule 3 */
            evdev_frame f;
            f.len = len;
            f.type = d->buf[3];
            f.seq = evdev_get_u16(d->buf + 4);
            memcpy(f.payload, d->buf + 6, len);
            d->stats.frames++;
            d->stats.frame_bytes += total;
            skip(d, total, 0);
            on_frame(ctx, &f);
            continue;
        }
        int inner = 0;
        for (uint8_t i = 1; i + 1 < total; i++) {
            if (d->buf[i] == EVDEV_SYNC0 && d->buf[i + 1] == EVDEV_SYNC1) {
                inner = 1;
                break;
            }
        }
        if (inner) {
            d->stats.truncated++;
        } else {
            d->stats.bad_crc++;
        }
        skip(d, 1, 1); /* only the first byte: a frame may start inside */
    }
}

void evdev_decoder_feed(evdev_decoder *d, const uint8_t *p, size_t n, evdev_on_frame on_frame, void *ctx) {
    for (size_t k = 0; k < n; k++) {
        d->stats.bytes++;
        d->buf[d->n++] = p[k]; /* room: drain leaves fewer than a frame's bytes */
        drain(d, on_frame, ctx);
    }
}
