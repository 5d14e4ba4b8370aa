/*
 * evdev: the device side of evflow's serial protocol, version 1
 * (docs/serial-protocol.md), in portable C11 — no dynamic memory, no RTOS,
 * no floating point except to pack the float fields of TOUCH and FORCE.
 *
 * A board provides five functions (struct evdev_board): bytes out to the
 * host, the sample to apply to the DAC, the finger's touch, the lateral
 * force (optional) and its own fault bits. The board's main loop hands
 * the core the bytes the host sent (evdev_device_receive) and calls
 * evdev_device_tick once per millisecond of its 1 kHz clock. docs/firmware.md
 * says how to port it to another board.
 */
#ifndef EVDEV_H
#define EVDEV_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- protocol constants (docs/serial-protocol.md) ---- */

#define EVDEV_VERSION 1u
#define EVDEV_SYNC0 0xA5u
#define EVDEV_SYNC1 0x5Au
#define EVDEV_MAX_PAYLOAD 64u
#define EVDEV_OVERHEAD 8u
#define EVDEV_MAX_FRAME (EVDEV_MAX_PAYLOAD + EVDEV_OVERHEAD)

/* Frame types. */
#define EVDEV_HELLO 0x01u
#define EVDEV_ACTUATION 0x10u
#define EVDEV_TOUCH 0x20u
#define EVDEV_FORCE 0x21u
#define EVDEV_HEARTBEAT 0x30u
#define EVDEV_FAULT 0x31u

/* HELLO roles and capability bits. */
#define EVDEV_ROLE_HOST 0u
#define EVDEV_ROLE_DEVICE 1u
#define EVDEV_CAP_ACTUATION 0x0001u
#define EVDEV_CAP_TOUCH 0x0002u
#define EVDEV_CAP_FORCE 0x0004u

/* Fault bits. */
#define EVDEV_FAULT_OVERCURRENT 0x0001u
#define EVDEV_FAULT_AMPLIFIER 0x0002u
#define EVDEV_FAULT_HOST_TIMEOUT 0x0004u
#define EVDEV_FAULT_TOUCH_SENSOR 0x0008u
#define EVDEV_FAULT_TEMPERATURE 0x0010u
#define EVDEV_FAULT_EMERGENCY_STOP 0x0020u
#define EVDEV_FAULT_OTHER 0x8000u

/* Device timing: the watchdog fires after more than this many ms without a
 * valid host frame, and ramps the output to zero over EVDEV_RAMP_MS ticks. */
#define EVDEV_WATCHDOG_MS 100u
#define EVDEV_RAMP_MS 10u
#define EVDEV_HEARTBEAT_MS 100u
/* Not engaged, hearing host frames: a HELLO at most this often (asks the
 * host, which took an earlier HELLO for its answer, for its own). */
#define EVDEV_PROMPT_MS 250u
/* ACTUATION samples waiting to be played; older ones are dropped. */
#define EVDEV_FIFO 8u

/* ---- CRC ---- */

/* CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, not reflected, no final XOR.
 * Check value: "123456789" -> 0x29B1. */
uint16_t evdev_crc16(const uint8_t *p, size_t n);

/* ---- frames ---- */

/* One received frame. */
typedef struct {
    uint8_t type;
    uint8_t len;
    uint16_t seq;
    uint8_t payload[EVDEV_MAX_PAYLOAD];
} evdev_frame;

/* Writes the frame (sync, len, type, seq, payload, CRC) to out, which holds
 * at least len + EVDEV_OVERHEAD bytes; returns its length, or 0 when len is
 * above EVDEV_MAX_PAYLOAD. */
size_t evdev_encode(uint8_t *out, uint8_t type, uint16_t seq, const uint8_t *payload, uint8_t len);

/* The payload length of a known frame type, or -1 for an unknown type. */
int evdev_payload_len(uint8_t type);

/* Little-endian fields (portable: no assumption on the CPU's byte order). */
void evdev_put_u16(uint8_t *p, uint16_t v);
void evdev_put_u32(uint8_t *p, uint32_t v);
void evdev_put_f32(uint8_t *p, float v);
uint16_t evdev_get_u16(const uint8_t *p);
uint32_t evdev_get_u32(const uint8_t *p);
float evdev_get_f32(const uint8_t *p);

/* ---- the receiver (the four rules of "Receiving") ---- */

typedef struct {
    uint32_t bytes;        /* bytes fed */
    uint32_t frames;       /* valid frames delivered */
    uint32_t frame_bytes;  /* bytes of valid frames */
    uint32_t garbage;      /* bytes discarded: part of no valid frame */
    uint32_t bad_crc;      /* candidates whose CRC did not match */
    uint32_t truncated;    /* candidates cut short by another sync pair */
    uint32_t bad_length;   /* sync pairs followed by a length above 64 */
} evdev_rx_stats;

/* Holds at most one frame's bytes. */
typedef struct {
    uint8_t buf[EVDEV_MAX_FRAME];
    uint8_t n;
    evdev_rx_stats stats;
} evdev_decoder;

typedef void (*evdev_on_frame)(void *ctx, const evdev_frame *f);

void evdev_decoder_init(evdev_decoder *d);
/* Takes n bytes, calling on_frame for each valid frame, in stream order.
 * Every byte ends up in exactly one of: a valid frame, the garbage count,
 * or the buffer (d->n). */
void evdev_decoder_feed(evdev_decoder *d, const uint8_t *p, size_t n, evdev_on_frame on_frame, void *ctx);

/* ---- the device ---- */

/* The finger as the touch sensor reads it. */
typedef struct {
    float x;        /* m, along the display's x axis */
    float y;        /* m */
    float load;     /* N, normal force */
    uint8_t touching;
} evdev_touch;

/* What a board provides. Every function is called from the core, in the
 * board's main loop (never from an interrupt). */
typedef struct {
    void *ctx;
    /* Queues bytes for the host (UART or USB) and returns at once: it must
     * never wait for the link — a host that went away (a USB port nobody
     * reads) would stall the tick and with it the watchdog. Drop a frame
     * that does not fit. At 1 kHz the core sends about 12 bytes per ms. */
    void (*write)(void *ctx, const uint8_t *bytes, size_t n);
    /* Applies an actuation sample now: +32767 = +1.0 = +50 V at the
     * amplifier's output, -32767 = -50 V, 0 = 0 V. */
    void (*dac)(void *ctx, int16_t sample);
    /* Reads the finger; returns 0 when the sensor does not answer. NULL
     * when the board has no touch sensor. */
    int (*touch)(void *ctx, evdev_touch *t);
    /* Reads the lateral force, N; returns 1 when one was measured. NULL
     * when the board measures none. */
    int (*force)(void *ctx, float *newtons);
    /* The board's own fault bits (overcurrent, supply, temperature,
     * emergency stop); NULL for none. */
    uint16_t (*faults)(void *ctx);
    /* Told each ACTUATION sample as it arrives, before the FIFO (for a
     * log); NULL for none. */
    void (*received)(void *ctx, int16_t sample);
} evdev_board;

/* Fixed settings. */
typedef struct {
    uint8_t version;        /* EVDEV_VERSION (tests use others) */
    uint16_t caps;          /* EVDEV_CAP_* it announces */
    uint16_t actuation_hz;  /* 1000 */
    uint16_t touch_hz;      /* 40 */
} evdev_config;

typedef struct {
    uint32_t hellos;          /* host HELLOs answered */
    uint32_t actuation;       /* ACTUATION frames received */
    uint32_t lost;            /* host frames missing by sequence number */
    uint32_t fifo_overflows;  /* samples dropped: FIFO full */
    uint32_t fifo_underruns;  /* ticks with an empty FIFO (last sample held) */
    uint32_t watchdog;        /* times the watchdog fired */
    uint32_t wrong_length;    /* frames whose payload length did not fit their type */
    uint32_t unknown_type;    /* frames of a type it does not know */
} evdev_counters;

typedef struct {
    const evdev_board *board;
    evdev_config config;
    evdev_decoder rx;
    evdev_counters counters;
    uint32_t ms;            /* ticks since power-up */
    uint32_t last_rx_ms;    /* tick of the last valid host frame */
    uint16_t seq_out;
    uint16_t seq_in;
    uint8_t seq_known;
    uint8_t engaged;        /* a host HELLO of our version arrived */
    uint16_t faults;
    int16_t u;              /* the sample being played */
    int16_t ramp_from;
    uint8_t ramp_left;
    uint8_t fifo_head;
    uint8_t fifo_len;
    int16_t fifo[EVDEV_FIFO];
    uint32_t next_touch_ms;
    uint32_t next_heartbeat_ms;
    uint32_t prompt_ms;     /* when it last said HELLO to a host it was not engaged with */
    uint8_t prompted;
} evdev_device;

/* The configuration of docs/serial-protocol.md: version 1, 1 kHz, 40 Hz,
 * with the capabilities given. */
evdev_config evdev_default_config(uint16_t caps);

/* Power-up: output zero, one HELLO (role device), nothing else until a host
 * HELLO arrives. */
void evdev_device_init(evdev_device *d, const evdev_board *board, evdev_config config);

/* Bytes the host sent (from the UART's receive ring). */
void evdev_device_receive(evdev_device *d, const uint8_t *p, size_t n);

/* One tick of the 1 kHz clock: faults, watchdog, the sample to the DAC,
 * then (engaged) FORCE each tick, TOUCH at touch_hz, HEARTBEAT at 10 Hz. */
void evdev_device_tick(evdev_device *d);

/* The host went away (a USB port closed): disengage and ramp to zero. */
void evdev_device_host_gone(evdev_device *d);

#ifdef __cplusplus
}
#endif

#endif
