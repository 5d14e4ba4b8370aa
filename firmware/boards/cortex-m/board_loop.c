/* The main loop every board here shares (board_loop.h). */
#include "board_loop.h"

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

void SysTick_Handler(void);

static volatile uint32_t ticks_due;

void SysTick_Handler(void) { ticks_due++; }

/* Bytes for the host wait here until the UART takes them: writing never
 * waits, so a host that went away cannot stall the tick and its watchdog. */
#define TX_RING 1024u
static uint8_t tx_ring[TX_RING];
static uint32_t tx_head, tx_len, tx_dropped;

void board_loop_write(void *ctx, const uint8_t *p, size_t n) {
    (void)ctx;
    if (n > TX_RING - tx_len) {
        tx_dropped++; /* the host counts it too, by sequence number */
        return;
    }
    for (size_t k = 0; k < n; k++) {
        tx_ring[(tx_head + tx_len) % TX_RING] = p[k];
        tx_len++;
    }
}

uint32_t board_loop_dropped(void) { return tx_dropped; }

void board_loop_run(evdev_device *d, const board_uart *u, uint32_t clock_hz) {
    SYST_RVR = clock_hz / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = 0x7u; /* processor clock, interrupt, enabled */
    for (;;) {
        while (tx_len && u->tx_ready()) {
            u->tx_byte(tx_ring[tx_head]);
            tx_head = (tx_head + 1u) % TX_RING;
            tx_len--;
        }
        uint8_t in[64];
        size_t n = 0;
        while (n < sizeof in && u->rx_ready()) {
            in[n++] = u->rx_byte();
        }
        if (n) {
            evdev_device_receive(d, in, n);
        }
        if (ticks_due) {
            __asm__ volatile("cpsid i");
            ticks_due--;
            __asm__ volatile("cpsie i");
            evdev_device_tick(d);
            if (u->after_tick) {
                u->after_tick(d);
            }
        }
    }
}
