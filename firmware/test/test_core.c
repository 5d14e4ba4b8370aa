/* Host unit tests of the firmware core (firmware/core): every frame type,
 * the CRC check value, the worked examples of docs/serial-protocol.md byte
 * for byte (the document is read, as nodes/src/serial/examples.rs reads it),
 * the receiver's resynchronization, sequence numbers that wrap, the FIFO,
 * the streaming cadence and the watchdog's ramp.
 *
 *   make -C firmware host-test   (or: cargo test -p evflow-tests --test end_to_end firmware_core)
 */
#include "../core/evdev.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;
static int checks;

#define CHECK(cond)                                                                 \
    do {                                                                            \
        checks++;                                                                   \
        if (!(cond)) {                                                              \
            failures++;                                                             \
            fprintf(stderr, "%s:%d: %s: failed: %s\n", __FILE__, __LINE__, __func__, #cond); \
        }                                                                           \
    } while (0)

/* ---- a board that records what the core does ---- */

#define OUT_CAP 200000
typedef struct {
    uint8_t out[OUT_CAP];
    size_t n_out;
    int16_t dac[20000];
    size_t n_dac;
    uint16_t faults;
    int touch_ok;
    int force_ok;
    float force;
} fake;

static void fake_write(void *ctx, const uint8_t *b, size_t n) {
    fake *f = (fake *)ctx;
    if (f->n_out + n <= OUT_CAP) {
        memcpy(f->out + f->n_out, b, n);
        f->n_out += n;
    }
}
static void fake_dac(void *ctx, int16_t s) {
    fake *f = (fake *)ctx;
    if (f->n_dac < sizeof f->dac / sizeof f->dac[0]) {
        f->dac[f->n_dac++] = s;
    }
}
static int fake_touch(void *ctx, evdev_touch *t) {
    fake *f = (fake *)ctx;
    t->x = 0.04f;
    t->y = 0.03f;
    t->load = 0.8f;
    t->touching = 1;
    return f->touch_ok;
}
static int fake_force(void *ctx, float *n) {
    fake *f = (fake *)ctx;
    *n = f->force;
    return f->force_ok;
}
static uint16_t fake_faults(void *ctx) { return ((fake *)ctx)->faults; }

static evdev_board board_of(fake *f) {
    evdev_board b = {f, fake_write, fake_dac, fake_touch, fake_force, fake_faults, NULL};
    return b;
}

/* Frames decoded from what the device wrote. */
typedef struct {
    evdev_frame f[4096];
    size_t n;
} frames;

static void collect(void *ctx, const evdev_frame *fr) {
    frames *c = (frames *)ctx;
    if (c->n < sizeof c->f / sizeof c->f[0]) {
        c->f[c->n++] = *fr;
    }
}

static void decode(const uint8_t *p, size_t n, frames *out, evdev_rx_stats *stats) {
    evdev_decoder d;
    evdev_decoder_init(&d);
    out->n = 0;
    evdev_decoder_feed(&d, p, n, collect, out);
    if (stats) {
        *stats = d.stats;
    }
}

static size_t count_type(const frames *c, uint8_t type) {
    size_t k = 0;
    for (size_t i = 0; i < c->n; i++) {
        k += c->f[i].type == type;
    }
    return k;
}

/* Host frames. */
static size_t host_hello(uint8_t *out, uint16_t seq, uint8_t version) {
    uint8_t p[8] = {version, EVDEV_ROLE_HOST, 0, 0, 0, 0, 0, 0};
    evdev_put_u16(p + 2, EVDEV_CAP_ACTUATION);
    evdev_put_u16(p + 4, 1000);
    evdev_put_u16(p + 6, 40);
    return evdev_encode(out, EVDEV_HELLO, seq, p, 8);
}
static size_t actuation(uint8_t *out, uint16_t seq, int16_t v) {
    uint8_t p[2];
    evdev_put_u16(p, (uint16_t)v);
    return evdev_encode(out, EVDEV_ACTUATION, seq, p, 2);
}

/* ---- tests ---- */

static void crc_check_value(void) {
    CHECK(evdev_crc16((const uint8_t *)"123456789", 9) == 0x29B1u);
    CHECK(evdev_crc16(NULL, 0) == 0xFFFFu);
}

/* The frames of "Worked examples", built by the encoder. */
static size_t example(const char *name, uint8_t *out) {
    uint8_t p[13];
    if (!strcmp(name, "hello-host")) {
        return host_hello(out, 0, 1);
    }
    if (!strcmp(name, "hello-device")) {
        p[0] = 1;
        p[1] = EVDEV_ROLE_DEVICE;
        evdev_put_u16(p + 2, EVDEV_CAP_TOUCH | EVDEV_CAP_FORCE);
        evdev_put_u16(p + 4, 1000);
        evdev_put_u16(p + 6, 40);
        return evdev_encode(out, EVDEV_HELLO, 0, p, 8);
    }
    if (!strcmp(name, "actuation")) {
        return actuation(out, 1, 16384); /* u = 0.5: 16383.5 rounded */
    }
    if (!strcmp(name, "touch")) {
        evdev_put_f32(p, 0.04f);
        evdev_put_f32(p + 4, 0.03f);
        evdev_put_f32(p + 8, 0.8f);
        p[12] = 1;
        return evdev_encode(out, EVDEV_TOUCH, 2, p, 13);
    }
    if (!strcmp(name, "force")) {
        evdev_put_f32(p, 0.25f);
        return evdev_encode(out, EVDEV_FORCE, 3, p, 4);
    }
    if (!strcmp(name, "heartbeat")) {
        evdev_put_u16(p, 0);
        evdev_put_u32(p + 2, 1500);
        return evdev_encode(out, EVDEV_HEARTBEAT, 4, p, 6);
    }
    if (!strcmp(name, "fault")) {
        evdev_put_u16(p, EVDEV_FAULT_OVERCURRENT);
        return evdev_encode(out, EVDEV_FAULT, 5, p, 2);
    }
    return 0;
}

static void worked_examples(const char *doc_path) {
    FILE *fp = fopen(doc_path, "r");
    CHECK(fp != NULL);
    if (!fp) {
        return;
    }
    static char doc[1 << 16];
    size_t n = fread(doc, 1, sizeof doc - 1, fp);
    fclose(fp);
    doc[n] = 0;
    const char *names[] = {"hello-host", "hello-device", "actuation", "touch", "force", "heartbeat", "fault"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        char marker[64];
        snprintf(marker, sizeof marker, "<!-- frame: %s -->", names[k]);
        const char *at = strstr(doc, marker);
        CHECK(at != NULL);
        if (!at) {
            continue;
        }
        const char *bytes = strstr(at, "```text\n");
        CHECK(bytes != NULL);
        if (!bytes) {
            continue;
        }
        bytes += 8;
        uint8_t want[EVDEV_MAX_FRAME];
        size_t nw = 0;
        while (*bytes && *bytes != '`' && nw < sizeof want) {
            unsigned v;
            int used;
            if (sscanf(bytes, " %2x%n", &v, &used) != 1) {
                break;
            }
            want[nw++] = (uint8_t)v;
            bytes += used;
            while (*bytes == ' ' || *bytes == '\n') {
                bytes++;
            }
        }
        uint8_t got[EVDEV_MAX_FRAME];
        size_t ng = example(names[k], got);
        CHECK(ng == nw && nw > 0 && memcmp(got, want, nw) == 0);
        if (ng != nw || memcmp(got, want, nw) != 0) {
            fprintf(stderr, "  example %s differs from the document\n", names[k]);
        }
    }
}

static void every_frame_type_round_trips(void) {
    uint8_t buf[EVDEV_MAX_FRAME * 8];
    size_t n = 0;
    const uint8_t types[] = {EVDEV_HELLO, EVDEV_ACTUATION, EVDEV_TOUCH, EVDEV_FORCE, EVDEV_HEARTBEAT, EVDEV_FAULT};
    for (size_t k = 0; k < sizeof types; k++) {
        uint8_t p[EVDEV_MAX_PAYLOAD];
        int len = evdev_payload_len(types[k]);
        for (int i = 0; i < len; i++) {
            p[i] = (uint8_t)(i * 37 + k);
        }
        n += evdev_encode(buf + n, types[k], (uint16_t)(65530u + k), p, (uint8_t)len);
    }
    static frames c;
    evdev_rx_stats st;
    decode(buf, n, &c, &st);
    CHECK(c.n == sizeof types);
    for (size_t k = 0; k < c.n; k++) {
        CHECK(c.f[k].type == types[k] && c.f[k].len == evdev_payload_len(types[k]));
        CHECK(c.f[k].seq == (uint16_t)(65530u + k));
        for (int i = 0; i < c.f[k].len; i++) {
            CHECK(c.f[k].payload[i] == (uint8_t)(i * 37 + k));
        }
    }
    CHECK(st.garbage == 0 && st.frame_bytes == n);
    /* Floats survive the little-endian packing. */
    uint8_t f4[4];
    evdev_put_f32(f4, -0.125f);
    CHECK(evdev_get_f32(f4) == -0.125f && f4[3] == 0xBE);
    CHECK(evdev_encode(buf, EVDEV_FORCE, 0, f4, 65) == 0);
    CHECK(evdev_payload_len(0x7F) == -1);
}

static void resync_after_garbage_and_a_damaged_length(void) {
    uint8_t s[512];
    size_t n = 0;
    const uint8_t junk[] = {0x00, 0xA5, 0x11, 0xA5, 0xA5, 0x5A, 0xFF, 0x42};
    memcpy(s, junk, sizeof junk);
    n += sizeof junk; /* garbage, a false sync, and a length of 255 */
    size_t a = n;
    n += actuation(s + n, 1, 100);
    n += actuation(s + n, 2, 200);
    size_t c0 = n;
    n += actuation(s + n, 3, 300);
    n += actuation(s + n, 4, 400);
    s[c0 + 2] = 64; /* frame 3's length byte damaged: a candidate of 72 bytes */
    for (int k = 5; k < 12; k++) {
        n += actuation(s + n, (uint16_t)k, (int16_t)(k * 100));
    }
    static frames c;
    evdev_rx_stats st;
    decode(s, n, &c, &st);
    /* Every frame but the damaged one, in order. */
    CHECK(c.n == 10);
    uint16_t want[] = {1, 2, 4, 5, 6, 7, 8, 9, 10, 11};
    for (size_t k = 0; k < c.n && k < 10; k++) {
        CHECK(c.f[k].seq == want[k]);
    }
    CHECK(st.bad_length == 1);
    CHECK(st.truncated + st.bad_crc >= 1);
    /* The books balance: every byte in a frame, the garbage or the buffer. */
    CHECK(st.bytes == n && st.frame_bytes + st.garbage == n);
    CHECK(st.garbage == a + 10 || st.garbage == a + 10u);
    /* A frame fed in pieces of any size decodes the same. */
    evdev_decoder d;
    evdev_decoder_init(&d);
    static frames c2;
    c2.n = 0;
    for (size_t k = 0; k < n; k += 3) {
        evdev_decoder_feed(&d, s + k, n - k < 3 ? n - k : 3, collect, &c2);
    }
    CHECK(c2.n == c.n && d.stats.frame_bytes == st.frame_bytes);
}

/* Every bit of a frame flipped in turn: the frame is refused and every
 * frame behind it is kept (behind a damaged length byte, once the 72 bytes
 * its candidate may span have arrived). */
static void a_flipped_bit_is_refused_and_the_next_frames_kept(void) {
    uint8_t s[256];
    size_t n = actuation(s, 7, 1234);
    size_t m = n;
    for (uint16_t k = 8; k < 20; k++) {
        m += actuation(s + m, k, (int16_t)k);
    }
    for (size_t bit = 16; bit < 8 * n; bit++) { /* every bit after the sync pair */
        uint8_t t[256];
        memcpy(t, s, m);
        t[bit / 8] ^= (uint8_t)(1u << (bit % 8));
        static frames c;
        evdev_rx_stats st;
        decode(t, m, &c, &st);
        CHECK(c.n == 12 && c.f[0].seq == 8 && c.f[11].seq == 19);
        CHECK(st.frame_bytes + st.garbage == m && st.frame_bytes == 12 * n);
    }
}

/* A device wired to a fake board, engaged by a host HELLO. */
static void engaged_device(evdev_device *d, fake *f, evdev_board *b, uint16_t caps) {
    memset(f, 0, sizeof *f);
    f->touch_ok = 1;
    f->force_ok = 1;
    f->force = 0.25f;
    *b = board_of(f);
    evdev_device_init(d, b, evdev_default_config(caps));
    uint8_t h[EVDEV_MAX_FRAME];
    evdev_device_receive(d, h, host_hello(h, 0, 1));
}

static void power_up_then_handshake(void) {
    fake f;
    memset(&f, 0, sizeof f);
    evdev_board b = board_of(&f);
    evdev_device d;
    evdev_device_init(&d, &b, evdev_default_config(EVDEV_CAP_ACTUATION | EVDEV_CAP_TOUCH | EVDEV_CAP_FORCE));
    CHECK(f.n_dac == 1 && f.dac[0] == 0);
    static frames c;
    decode(f.out, f.n_out, &c, NULL);
    CHECK(c.n == 1 && c.f[0].type == EVDEV_HELLO && c.f[0].payload[1] == EVDEV_ROLE_DEVICE);
    for (int k = 0; k < 50; k++) {
        evdev_device_tick(&d); /* not engaged: silent, output zero */
    }
    decode(f.out, f.n_out, &c, NULL);
    CHECK(c.n == 1 && f.dac[49] == 0);
    /* Frames before any host HELLO: a HELLO asks for one, at most every
     * 250 ticks. */
    uint8_t a[16];
    size_t before = f.n_out;
    for (int k = 0; k < 600; k++) {
        evdev_device_receive(&d, a, actuation(a, (uint16_t)(k + 1), 100));
        evdev_device_tick(&d);
    }
    decode(f.out + before, f.n_out - before, &c, NULL);
    CHECK(c.n == 3 && count_type(&c, EVDEV_HELLO) == 3); /* ticks 50, 300, 550 */
    CHECK(d.counters.actuation == 0);
    /* Another version: answered, not engaged. */
    uint8_t h[EVDEV_MAX_FRAME];
    evdev_device_receive(&d, h, host_hello(h, 0, 2));
    CHECK(!d.engaged && d.counters.hellos == 1);
    evdev_device_receive(&d, h, host_hello(h, 1, 1));
    CHECK(d.engaged);
    decode(f.out, f.n_out, &c, NULL);
    CHECK(count_type(&c, EVDEV_HELLO) == 6);
}

static void streaming_cadence(void) {
    static fake f;
    evdev_board b;
    evdev_device d;
    engaged_device(&d, &f, &b, EVDEV_CAP_ACTUATION | EVDEV_CAP_TOUCH | EVDEV_CAP_FORCE);
    uint8_t a[16];
    for (int k = 0; k < 1000; k++) {
        evdev_device_receive(&d, a, actuation(a, (uint16_t)(k + 1), 0)); /* the host keeps it alive */
        evdev_device_tick(&d);
    }
    static frames c;
    decode(f.out, f.n_out, &c, NULL);
    CHECK(count_type(&c, EVDEV_FORCE) == 1000);
    CHECK(count_type(&c, EVDEV_TOUCH) == 40);
    CHECK(count_type(&c, EVDEV_HEARTBEAT) == 10);
    CHECK(count_type(&c, EVDEV_FAULT) == 0);
    /* One wrapping sequence number over every frame. */
    for (size_t k = 1; k < c.n; k++) {
        CHECK(c.f[k].seq == (uint16_t)(c.f[k - 1].seq + 1u));
    }
    /* A touch frame carries the finger. */
    for (size_t k = 0; k < c.n; k++) {
        if (c.f[k].type == EVDEV_TOUCH) {
            CHECK(evdev_get_f32(c.f[k].payload + 8) == 0.8f && c.f[k].payload[12] == 1);
            break;
        }
    }
    CHECK(d.counters.lost == 0 && d.counters.actuation == 1000);
}

static void fifo_plays_in_order_and_holds_the_last(void) {
    static fake f;
    evdev_board b;
    evdev_device d;
    engaged_device(&d, &f, &b, EVDEV_CAP_ACTUATION);
    uint8_t a[64];
    size_t n = 0;
    n += actuation(a + n, 1, 100);
    n += actuation(a + n, 2, -200);
    n += actuation(a + n, 3, 300);
    evdev_device_receive(&d, a, n);
    size_t before = f.n_dac;
    for (int k = 0; k < 5; k++) {
        evdev_device_tick(&d);
    }
    CHECK(f.dac[before] == 100 && f.dac[before + 1] == -200 && f.dac[before + 2] == 300);
    CHECK(f.dac[before + 3] == 300 && f.dac[before + 4] == 300);
    CHECK(d.counters.fifo_underruns == 2);
    /* More than the FIFO holds between two ticks: the oldest are dropped. */
    n = 0;
    for (int k = 0; k < (int)EVDEV_FIFO + 3; k++) {
        n += actuation(a + 0, (uint16_t)(4 + k), (int16_t)(1000 + k));
        evdev_device_receive(&d, a, n);
        n = 0;
    }
    CHECK(d.counters.fifo_overflows == 3);
    evdev_device_tick(&d);
    CHECK(f.dac[f.n_dac - 1] == 1003);
}

static void sequence_numbers_wrap(void) {
    static fake f;
    evdev_board b;
    evdev_device d;
    engaged_device(&d, &f, &b, EVDEV_CAP_ACTUATION | EVDEV_CAP_FORCE);
    uint8_t a[16];
    const uint16_t seqs[] = {65534, 65535, 0, 1};
    uint8_t h[EVDEV_MAX_FRAME];
    evdev_device_receive(&d, h, host_hello(h, 65533, 1));
    for (size_t k = 0; k < 4; k++) {
        evdev_device_receive(&d, a, actuation(a, seqs[k], 1));
    }
    CHECK(d.counters.lost == 0);
    evdev_device_receive(&d, a, actuation(a, 4, 1)); /* 2 and 3 lost */
    CHECK(d.counters.lost == 2);
    /* The device's own number wraps too. */
    d.seq_out = 65535;
    f.n_out = 0;
    evdev_device_tick(&d);
    evdev_device_tick(&d);
    static frames c;
    decode(f.out, f.n_out, &c, NULL);
    CHECK(c.n >= 2 && c.f[0].seq == 65535 && c.f[1].seq == 0);
}

static void watchdog_ramps_to_zero_in_10_ms_and_reports(void) {
    static fake f;
    evdev_board b;
    evdev_device d;
    engaged_device(&d, &f, &b, EVDEV_CAP_ACTUATION);
    uint8_t a[16];
    evdev_device_receive(&d, a, actuation(a, 1, 20000)); /* at tick 0 */
    size_t first = f.n_dac;
    for (int k = 1; k <= 120; k++) {
        evdev_device_tick(&d); /* tick k */
    }
    /* Played at tick 1, held to tick 100, then 10 steps down. */
    CHECK(f.dac[first] == 20000);
    CHECK(f.dac[first + 99] == 20000); /* tick 100: not yet fired */
    CHECK(f.dac[first + 100] == 18000); /* tick 101: 9/10 */
    CHECK(f.dac[first + 108] == 2000);
    CHECK(f.dac[first + 109] == 0); /* tick 110: zero */
    for (int k = 101; k < 110; k++) {
        CHECK(f.dac[first + k] <= f.dac[first + k - 1]);
    }
    CHECK(d.faults == EVDEV_FAULT_HOST_TIMEOUT && d.counters.watchdog == 1);
    static frames c;
    decode(f.out, f.n_out, &c, NULL);
    CHECK(count_type(&c, EVDEV_FAULT) == 1);
    /* Samples are ignored while the fault is set; the next HELLO clears it. */
    evdev_device_receive(&d, a, actuation(a, 2, 5000));
    evdev_device_tick(&d);
    CHECK(f.dac[f.n_dac - 1] == 0);
    uint8_t h[EVDEV_MAX_FRAME];
    evdev_device_receive(&d, h, host_hello(h, 3, 1));
    CHECK(d.faults == 0);
    decode(f.out, f.n_out, &c, NULL);
    CHECK(count_type(&c, EVDEV_FAULT) == 2);
    /* The host gone (a port closed): the same ramp. */
    evdev_device_receive(&d, a, actuation(a, 4, -10000));
    evdev_device_tick(&d);
    evdev_device_host_gone(&d);
    for (int k = 0; k < 10; k++) {
        evdev_device_tick(&d);
    }
    CHECK(f.dac[f.n_dac - 1] == 0 && f.dac[f.n_dac - 10] == -9000);
}

static void board_faults_are_reported_on_change(void) {
    static fake f;
    evdev_board b;
    evdev_device d;
    engaged_device(&d, &f, &b, EVDEV_CAP_ACTUATION | EVDEV_CAP_TOUCH);
    uint8_t a[16];
    f.faults = EVDEV_FAULT_OVERCURRENT;
    for (int k = 0; k < 3; k++) {
        evdev_device_receive(&d, a, actuation(a, (uint16_t)(k + 1), 0));
        evdev_device_tick(&d);
    }
    f.faults = 0;
    f.touch_ok = 0; /* the touch sensor stops answering */
    for (int k = 0; k < 30; k++) {
        evdev_device_receive(&d, a, actuation(a, (uint16_t)(k + 4), 0));
        evdev_device_tick(&d);
    }
    static frames c;
    decode(f.out, f.n_out, &c, NULL);
    uint16_t seen[8];
    size_t ns = 0;
    for (size_t k = 0; k < c.n && ns < 8; k++) {
        if (c.f[k].type == EVDEV_FAULT) {
            seen[ns++] = evdev_get_u16(c.f[k].payload);
        }
    }
    CHECK(ns == 3);
    CHECK(ns == 3 && seen[0] == EVDEV_FAULT_OVERCURRENT && seen[1] == 0 && seen[2] == EVDEV_FAULT_TOUCH_SENSOR);
}

static void random_bytes_never_break_the_books(void) {
    uint32_t x = 12345;
    static uint8_t s[100000];
    for (size_t k = 0; k < sizeof s; k++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        s[k] = (uint8_t)(x % 7 == 0 ? 0xA5 : x % 7 == 1 ? 0x5A : x >> 8);
    }
    evdev_decoder d;
    evdev_decoder_init(&d);
    static frames c;
    c.n = 0;
    evdev_decoder_feed(&d, s, sizeof s, collect, &c);
    CHECK(d.stats.bytes == sizeof s);
    CHECK(d.stats.frame_bytes + d.stats.garbage + d.n == sizeof s);
    CHECK(d.n < EVDEV_MAX_FRAME);
}

int main(int argc, char **argv) {
    const char *doc = argc > 1 ? argv[1] : "../docs/serial-protocol.md";
    crc_check_value();
    worked_examples(doc);
    every_frame_type_round_trips();
    resync_after_garbage_and_a_damaged_length();
    a_flipped_bit_is_refused_and_the_next_frames_kept();
    power_up_then_handshake();
    streaming_cadence();
    fifo_plays_in_order_and_holds_the_last();
    sequence_numbers_wrap();
    watchdog_ramps_to_zero_in_10_ms_and_reports();
    board_faults_are_reported_on_change();
    random_bytes_never_break_the_books();
    printf("firmware core: %d checks, %d failed\n", checks, failures);
    return failures ? 1 : 0;
}
