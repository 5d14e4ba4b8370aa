/* The device checklist of docs/serial-protocol.md as a state machine
 * clocked by the board's 1 kHz tick. */
#include "evdev.h"

#include <string.h>

evdev_config evdev_default_config(uint16_t caps) {
    evdev_config c;
    c.version = EVDEV_VERSION;
    c.caps = caps;
    c.actuation_hz = 1000;
    c.touch_hz = 40;
    return c;
}

/* Sends one numbered frame. */
static void send(evdev_device *d, uint8_t type, const uint8_t *payload, uint8_t len) {
    uint8_t out[EVDEV_MAX_FRAME];
    size_t n = evdev_encode(out, type, d->seq_out, payload, len);
    if (n) {
        d->board->write(d->board->ctx, out, n);
        d->seq_out = (uint16_t)(d->seq_out + 1u);
    }
}

static void send_hello(evdev_device *d) {
    uint8_t p[8];
    p[0] = d->config.version;
    p[1] = EVDEV_ROLE_DEVICE;
    evdev_put_u16(p + 2, d->config.caps);
    evdev_put_u16(p + 4, d->config.actuation_hz);
    evdev_put_u16(p + 6, d->config.touch_hz);
    send(d, EVDEV_HELLO, p, 8);
}

/* Sets the fault bits; a change is reported at once (while engaged, or
 * when it is the watchdog's). */
static void set_faults(evdev_device *d, uint16_t bits) {
    if (bits == d->faults) {
        return;
    }
    d->faults = bits;
    if (d->engaged || (bits & EVDEV_FAULT_HOST_TIMEOUT)) {
        uint8_t p[2];
        evdev_put_u16(p, bits);
        send(d, EVDEV_FAULT, p, 2);
    }
}

static void fifo_clear(evdev_device *d) {
    d->fifo_head = 0;
    d->fifo_len = 0;
}

static void start_ramp(evdev_device *d) {
    if (d->ramp_left == 0 && d->u != 0) {
        d->ramp_left = EVDEV_RAMP_MS;
        d->ramp_from = d->u;
    }
}

void evdev_device_init(evdev_device *d, const evdev_board *board, evdev_config config) {
    memset(d, 0, sizeof *d);
    d->board = board;
    d->config = config;
    evdev_decoder_init(&d->rx);
    board->dac(board->ctx, 0);
    send_hello(d);
}

/* One valid frame from the host. */
static void on_frame(void *ctx, const evdev_frame *f) {
    evdev_device *d = (evdev_device *)ctx;
    int want = evdev_payload_len(f->type);
    if (want < 0) {
        d->counters.unknown_type++;
        return;
    }
    if (want != f->len) {
        d->counters.wrong_length++;
        return;
    }
    if (d->seq_known) {
        uint16_t gap = (uint16_t)(f->seq - d->seq_in);
        if (gap < 0x8000u) {
            d->counters.lost += gap;
        }
    }
    d->seq_in = (uint16_t)(f->seq + 1u);
    d->seq_known = 1;
    if (f->type == EVDEV_HELLO && f->payload[1] == EVDEV_ROLE_HOST) {
        d->counters.hellos++;
        send_hello(d);
        if (f->payload[0] == d->config.version) {
            d->engaged = 1;
            d->last_rx_ms = d->ms;
            d->next_touch_ms = d->ms + 1u; /* both on the next tick, then at their rates */
            d->next_heartbeat_ms = d->ms + 1u;
            if (d->faults & EVDEV_FAULT_HOST_TIMEOUT) {
                set_faults(d, (uint16_t)(d->faults & ~EVDEV_FAULT_HOST_TIMEOUT));
            }
        } else {
            d->engaged = 0; /* another version: answered, idle, output zero */
            fifo_clear(d);
            start_ramp(d);
        }
        return;
    }
    if (!d->engaged) {
        /* A host streaming to a device it never said HELLO to (its HELLO
         * lost, or our power-up HELLO taken for an answer): ask for one. */
        if (!d->prompted || d->ms - d->prompt_ms >= EVDEV_PROMPT_MS) {
            d->prompted = 1;
            d->prompt_ms = d->ms;
            send_hello(d);
        }
        return;
    }
    d->last_rx_ms = d->ms;
    if (f->type != EVDEV_ACTUATION) {
        return;
    }
    d->counters.actuation++;
    if (d->board->received) {
        d->board->received(d->board->ctx, (int16_t)evdev_get_u16(f->payload));
    }
    if (d->faults & EVDEV_FAULT_HOST_TIMEOUT) {
        return; /* not played until the next HELLO */
    }
    if (d->fifo_len == EVDEV_FIFO) {
        d->fifo_head = (uint8_t)((d->fifo_head + 1u) % EVDEV_FIFO);
        d->fifo_len--;
        d->counters.fifo_overflows++;
    }
    d->fifo[(d->fifo_head + d->fifo_len) % EVDEV_FIFO] = (int16_t)evdev_get_u16(f->payload);
    d->fifo_len++;
}

void evdev_device_receive(evdev_device *d, const uint8_t *p, size_t n) {
    evdev_decoder_feed(&d->rx, p, n, on_frame, d);
}

void evdev_device_host_gone(evdev_device *d) {
    d->engaged = 0;
    d->seq_known = 0;
    fifo_clear(d);
    start_ramp(d);
}

/* The sample for this tick. */
static void play(evdev_device *d) {
    if (d->engaged && !(d->faults & EVDEV_FAULT_HOST_TIMEOUT) && d->ms - d->last_rx_ms > EVDEV_WATCHDOG_MS) {
        d->counters.watchdog++;
        set_faults(d, (uint16_t)(d->faults | EVDEV_FAULT_HOST_TIMEOUT));
        fifo_clear(d);
        start_ramp(d);
    }
    if (d->ramp_left > 0) {
        d->ramp_left--;
        d->u = (int16_t)((int32_t)d->ramp_from * d->ramp_left / (int32_t)EVDEV_RAMP_MS);
    } else if (!d->engaged || (d->faults & EVDEV_FAULT_HOST_TIMEOUT)) {
        /* idle: nothing plays */
    } else if (d->fifo_len > 0) {
        d->u = d->fifo[d->fifo_head];
        d->fifo_head = (uint8_t)((d->fifo_head + 1u) % EVDEV_FIFO);
        d->fifo_len--;
    } else {
        d->counters.fifo_underruns++;
    }
    d->board->dac(d->board->ctx, d->u);
}

void evdev_device_tick(evdev_device *d) {
    const evdev_board *b = d->board;
    d->ms++;
    uint16_t hw = b->faults ? (uint16_t)(b->faults(b->ctx) & ~EVDEV_FAULT_HOST_TIMEOUT & ~EVDEV_FAULT_TOUCH_SENSOR) : 0u;
    evdev_touch t;
    int touched = 0;
    uint16_t sensor = 0;
    int touch_due = d->engaged && (d->config.caps & EVDEV_CAP_TOUCH) && b->touch && d->ms - d->next_touch_ms < 0x80000000u;
    if (touch_due) {
        touched = b->touch(b->ctx, &t);
        sensor = touched ? 0u : (uint16_t)EVDEV_FAULT_TOUCH_SENSOR;
    } else {
        sensor = (uint16_t)(d->faults & EVDEV_FAULT_TOUCH_SENSOR);
    }
    set_faults(d, (uint16_t)(hw | sensor | (d->faults & EVDEV_FAULT_HOST_TIMEOUT)));
    play(d);
    if (!d->engaged) {
        return;
    }
    float force;
    if ((d->config.caps & EVDEV_CAP_FORCE) && b->force && b->force(b->ctx, &force)) {
        uint8_t p[4];
        evdev_put_f32(p, force);
        send(d, EVDEV_FORCE, p, 4);
    }
    if (touch_due) {
        uint32_t period = d->config.touch_hz ? 1000u / d->config.touch_hz : 1000u;
        d->next_touch_ms += period;
        if (touched) {
            uint8_t p[13];
            evdev_put_f32(p, t.x);
            evdev_put_f32(p + 4, t.y);
            evdev_put_f32(p + 8, t.load);
            p[12] = t.touching ? 1u : 0u;
            send(d, EVDEV_TOUCH, p, 13);
        }
    }
    if (d->ms - d->next_heartbeat_ms < 0x80000000u) {
        d->next_heartbeat_ms += EVDEV_HEARTBEAT_MS;
        uint8_t p[6];
        evdev_put_u16(p, d->faults);
        evdev_put_u32(p + 2, d->ms);
        send(d, EVDEV_HEARTBEAT, p, 6);
    }
}
