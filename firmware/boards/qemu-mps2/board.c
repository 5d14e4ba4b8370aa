/* The emulated board: QEMU's mps2-an385 (an ARM MPS2 with a Cortex-M3).
 *
 *   qemu-system-arm -M mps2-an385 -display none -monitor none \
 *       -serial pty -semihosting-config enable=on,target=native \
 *       -kernel build/qemu-mps2.elf
 *
 * UART0 (CMSDK APB UART) is the link to the host: QEMU puts it on a pty.
 * SysTick at 25 MHz / 25 000 is the 1 kHz tick. There is no DAC: each
 * sample the core applies is appended to `dac.bin` (int16 little endian,
 * one per tick) and each ACTUATION sample received to `rx.bin` (u32 tick,
 * i32 sample) in QEMU's working folder, through semihosting, where a test
 * reads them back, with the device's counters (`stats.bin`, every 500
 * ticks). The finger is a scripted stroke: 8 cm side to side at
 * 5 cm/s, y = 3 cm, 0.8 N. No force sensor. */
#include "../cortex-m/board_loop.h"

#include <stdint.h>

/* ---- CMSDK APB UART0 ---- */
#define UART0 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0 + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0 + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0 + 0x08u))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0 + 0x10u))
#define UART_TX_FULL 0x1u
#define UART_RX_FULL 0x2u

#define SYSCLK_HZ 25000000u

/* ---- semihosting ---- */
#define SYS_OPEN 0x01u
#define SYS_CLOSE 0x02u
#define SYS_WRITE 0x05u

static int semihost(uint32_t op, const void *arg) {
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return (int)r0;
}

static int open_write(const char *name, uint32_t len) {
    uint32_t args[3] = {(uint32_t)name, 5u /* "wb" */, len};
    return semihost(SYS_OPEN, args);
}

static void write_file(int handle, const void *p, uint32_t n) {
    uint32_t args[3] = {(uint32_t)handle, (uint32_t)p, n};
    (void)semihost(SYS_WRITE, args);
}

/* The device's counters, rewritten to `stats.bin` (u32 little endian:
 * ticks, then evdev_rx_stats' seven fields, then evdev_counters' eight,
 * then the tick of the last valid host frame). */
static void write_stats(const evdev_device *d) {
    uint32_t v[17] = {d->ms, d->rx.stats.bytes, d->rx.stats.frames, d->rx.stats.frame_bytes, d->rx.stats.garbage,
                      d->rx.stats.bad_crc, d->rx.stats.truncated, d->rx.stats.bad_length, d->counters.hellos,
                      d->counters.actuation, d->counters.lost, d->counters.fifo_overflows, d->counters.fifo_underruns,
                      d->counters.watchdog, d->counters.wrong_length, d->counters.unknown_type, d->last_rx_ms};
    uint8_t b[68];
    for (uint32_t k = 0; k < 17u; k++) {
        evdev_put_u32(b + 4u * k, v[k]);
    }
    int h = open_write("stats.bin", 9);
    if (h >= 0) {
        write_file(h, b, sizeof b);
        uint32_t args[1] = {(uint32_t)h};
        (void)semihost(SYS_CLOSE, args);
    }
}

/* A log flushed every LOG_BYTES bytes and every 50 ticks. */
#define LOG_BYTES 512u
typedef struct {
    int handle;
    uint32_t n;
    uint8_t buf[LOG_BYTES];
} log_file;

static void log_flush(log_file *l) {
    if (l->n && l->handle >= 0) {
        write_file(l->handle, l->buf, l->n);
    }
    l->n = 0;
}

static void log_put(log_file *l, const void *rec, uint32_t size) {
    const uint8_t *r = (const uint8_t *)rec;
    for (uint32_t k = 0; k < size; k++) {
        l->buf[l->n++] = r[k];
    }
    if (l->n + size > LOG_BYTES) {
        log_flush(l);
    }
}

/* ---- the board ---- */

static log_file dac_log, rx_log;
static evdev_device device;

static int rx_ready(void) { return (UART_STATE & UART_RX_FULL) != 0; }
static uint8_t rx_byte(void) { return (uint8_t)UART_DATA; }
static int tx_ready(void) { return (UART_STATE & UART_TX_FULL) == 0; }
static void tx_byte(uint8_t b) { UART_DATA = b; }

/* The logs at most 50 ticks behind, the counters every 500. */
static void after_tick(const evdev_device *d) {
    if (d->ms % 50u == 0) {
        log_flush(&dac_log);
        log_flush(&rx_log);
    }
    if (d->ms % 500u == 0) {
        write_stats(d);
    }
}

static void dac(void *ctx, int16_t sample) {
    (void)ctx;
    uint8_t b[2] = {(uint8_t)((uint16_t)sample & 0xFFu), (uint8_t)((uint16_t)sample >> 8)};
    log_put(&dac_log, b, 2);
}

static void received(void *ctx, int16_t sample) {
    (void)ctx;
    uint8_t b[8];
    evdev_put_u32(b, device.ms);
    evdev_put_u32(b + 4, (uint32_t)(int32_t)sample);
    log_put(&rx_log, b, 8);
}

/* The scripted stroke at the device's own clock. */
static int touch(void *ctx, evdev_touch *t) {
    (void)ctx;
    uint32_t period_ms = 3200u; /* 16 cm at 5 cm/s: there and back */
    uint32_t phase = device.ms % period_ms;
    float s = (float)(phase < period_ms / 2u ? phase : period_ms - phase) / 1000.0f; /* s along the pass */
    t->x = 0.05f * s;
    t->y = 0.03f;
    t->load = 0.8f;
    t->touching = 1;
    return 1;
}

int main(void) {
    dac_log.handle = open_write("dac.bin", 7);
    rx_log.handle = open_write("rx.bin", 6);
    UART_BAUDDIV = SYSCLK_HZ / 921600u;
    UART_CTRL = 0x3u; /* TX and RX enabled, no interrupts: polled */
    static const evdev_board board = {0, board_loop_write, dac, touch, 0, 0, received};
    static const board_uart uart = {rx_ready, rx_byte, tx_ready, tx_byte, after_tick};
    evdev_device_init(&device, &board, evdev_default_config(EVDEV_CAP_ACTUATION | EVDEV_CAP_TOUCH));
    board_loop_run(&device, &uart, SYSCLK_HZ);
    return 0;
}
