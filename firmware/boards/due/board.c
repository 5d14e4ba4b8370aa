/* Arduino Due (Atmel SAM3X8E, Cortex-M3).
 *
 * Link: the programming port — the UART on PA8/PA9, which the board's
 * ATmega16U2 bridges to a USB CDC port on the computer (/dev/ttyACM0) —
 * at 250 000 baud (exact on both ends: 12 MHz / (16 · 3) here, 16 MHz /
 * (8 · 8) on the 16U2); evflow: `--set baud=250000`. The native USB port
 * would need a USB device stack in the firmware; the bridge needs none.
 * Analog out: DAC0 (DACC channel 0), 12 bits, 1/6 to 5/6 of 3.3 V
 * (0.55–2.75 V) — the amplifier's input stage must take that range to
 * ±50 V (docs/firmware.md, "Wiring").
 * Clock: the 12 MHz internal RC oscillator (no crystal set-up; 12 000
 * cycles per tick are ample for the core). SysTick: 1 kHz.
 * No touch or force sensor on the board: a lab wires its own and fills in
 * touch() / force() (and announces EVDEV_CAP_TOUCH / _FORCE).
 *
 * Not run on hardware here: it compiles in CI; the register settings
 * follow the SAM3X datasheet (Atmel 11057). */
#include "../cortex-m/board_loop.h"

#include <stdint.h>

#define REG(a) (*(volatile uint32_t *)(a))

/* Watchdog (on at reset). */
#define WDT_MR REG(0x400E1A54u)
/* Power management. */
#define PMC_PCER0 REG(0x400E0610u)
#define PMC_PCER1 REG(0x400E0700u)
#define CKGR_MOR REG(0x400E0620u)
#define PMC_SR REG(0x400E0668u)
/* PIOA: PA8 URXD, PA9 UTXD (peripheral A). */
#define PIOA_PDR REG(0x400E0E04u)
#define PIOA_ABSR REG(0x400E0E70u)
/* UART. */
#define UART_CR REG(0x400E0800u)
#define UART_MR REG(0x400E0804u)
#define UART_SR REG(0x400E0814u)
#define UART_RHR REG(0x400E0818u)
#define UART_THR REG(0x400E081Cu)
#define UART_BRGR REG(0x400E0820u)
/* DACC. */
#define DACC_CR REG(0x400C8000u)
#define DACC_MR REG(0x400C8004u)
#define DACC_CHER REG(0x400C8010u)
#define DACC_CDR REG(0x400C8020u)

#define MCK_HZ 12000000u
#define BAUD 250000u
#define ID_UART 8u
#define ID_PIOA 11u
#define ID_DACC 38u

static int rx_ready(void) { return (UART_SR & 1u) != 0; } /* RXRDY */
static uint8_t rx_byte(void) { return (uint8_t)UART_RHR; }
static int tx_ready(void) { return (UART_SR & (1u << 1)) != 0; } /* TXRDY */
static void tx_byte(uint8_t b) { UART_THR = b; }

/* ±32767 → 0 … 4095 (mid-scale 2048 = 0 V at the amplifier). */
static void dac(void *ctx, int16_t sample) {
    (void)ctx;
    DACC_CDR = (uint32_t)(((int32_t)sample + 32768) >> 4);
}

int main(void) {
    WDT_MR = 1u << 15; /* WDDIS */
    /* Fast RC at 12 MHz (it is the main clock after reset, at 4 MHz). */
    CKGR_MOR = (0x37u << 16) | (1u << 3) | (2u << 4) | (CKGR_MOR & 1u);
    while (!(PMC_SR & (1u << 17))) { /* MOSCRCS */
    }
    PMC_PCER0 = (1u << ID_UART) | (1u << ID_PIOA);
    PMC_PCER1 = 1u << (ID_DACC - 32u);
    PIOA_ABSR &= ~((1u << 8) | (1u << 9));
    PIOA_PDR = (1u << 8) | (1u << 9);
    UART_CR = (1u << 2) | (1u << 3); /* reset RX, TX */
    UART_MR = 4u << 9;               /* no parity, normal mode */
    UART_BRGR = MCK_HZ / (16u * BAUD);
    UART_CR = (1u << 4) | (1u << 6); /* RXEN, TXEN */
    DACC_CR = 1u;                    /* software reset */
    DACC_MR = (8u << 24);            /* free running, channel 0, start-up time */
    DACC_CHER = 1u;
    static evdev_device device;
    static const evdev_board board = {0, board_loop_write, dac, 0, 0, 0, 0};
    static const board_uart uart = {rx_ready, rx_byte, tx_ready, tx_byte, 0};
    evdev_device_init(&device, &board, evdev_default_config(EVDEV_CAP_ACTUATION));
    board_loop_run(&device, &uart, MCK_HZ);
    return 0;
}
