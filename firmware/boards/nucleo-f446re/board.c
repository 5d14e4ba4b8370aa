/* ST NUCLEO-F446RE (STM32F446RE, Cortex-M4).
 *
 * Link: USART2 on PA2/PA3, wired to the on-board ST-LINK's virtual COM
 * port (/dev/ttyACM0 on the computer), at 460 800 baud (16 MHz / 35: 0.8 %
 * off); evflow: `--set baud=460800`.
 * Analog out: DAC1 channel 1 on PA4 (Arduino header A2), 12 bits, 0 to
 * 3.3 V, mid-scale for 0 V at the amplifier (docs/firmware.md, "Wiring").
 * Clock: the 16 MHz internal RC (HSI, the reset clock; no PLL set-up).
 * SysTick: 1 kHz. Soft float (the FPU is left off).
 * No touch or force sensor on the board: a lab wires its own and fills in
 * touch() / force() (and announces EVDEV_CAP_TOUCH / _FORCE).
 *
 * Not run on hardware here: it compiles in CI; the register settings
 * follow the STM32F446 reference manual (RM0390). */
#include "../../core/evdev.h"

#include <stdint.h>

#define REG(a) (*(volatile uint32_t *)(a))

#define RCC_AHB1ENR REG(0x40023830u)
#define RCC_APB1ENR REG(0x40023840u)
#define GPIOA_MODER REG(0x40020000u)
#define GPIOA_AFRL REG(0x40020020u)
#define USART2_SR REG(0x40004400u)
#define USART2_DR REG(0x40004404u)
#define USART2_BRR REG(0x40004408u)
#define USART2_CR1 REG(0x4000440Cu)
#define DAC_CR REG(0x40007400u)
#define DAC_DHR12R1 REG(0x40007408u)
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)

#define HSI_HZ 16000000u
#define BAUD 460800u

static volatile uint32_t ticks_due;
static evdev_device device;

void SysTick_Handler(void) { ticks_due++; }

/* Transmit ring drained as the USART takes bytes: writing never waits. */
#define TX_RING 1024u
static uint8_t tx_ring[TX_RING];
static uint32_t tx_head, tx_len;

static void uart_write(void *ctx, const uint8_t *p, size_t n) {
    (void)ctx;
    if (n > TX_RING - tx_len) {
        return; /* dropped whole: the host counts it by sequence number */
    }
    for (size_t k = 0; k < n; k++) {
        tx_ring[(tx_head + tx_len) % TX_RING] = p[k];
        tx_len++;
    }
}

static void uart_drain(void) {
    while (tx_len && (USART2_SR & (1u << 7))) { /* TXE */
        USART2_DR = tx_ring[tx_head];
        tx_head = (tx_head + 1u) % TX_RING;
        tx_len--;
    }
}

/* ±32767 → 0 … 4095 (mid-scale 2048 = 0 V at the amplifier). */
static void dac(void *ctx, int16_t sample) {
    (void)ctx;
    DAC_DHR12R1 = (uint32_t)(((int32_t)sample + 32768) >> 4);
}

int main(void) {
    RCC_AHB1ENR |= 1u;                       /* GPIOA */
    RCC_APB1ENR |= (1u << 17) | (1u << 29); /* USART2, DAC */
    /* PA2, PA3: alternate function 7 (USART2); PA4: analog (DAC). */
    GPIOA_MODER = (GPIOA_MODER & ~(0x3Fu << 4)) | (2u << 4) | (2u << 6) | (3u << 8);
    GPIOA_AFRL = (GPIOA_AFRL & ~(0xFFu << 8)) | (7u << 8) | (7u << 12);
    USART2_BRR = (HSI_HZ + BAUD / 2u) / BAUD;
    USART2_CR1 = (1u << 13) | (1u << 3) | (1u << 2); /* UE, TE, RE */
    DAC_CR = 1u;                                     /* EN1 */
    static const evdev_board board = {0, uart_write, dac, 0, 0, 0, 0};
    evdev_device_init(&device, &board, evdev_default_config(EVDEV_CAP_ACTUATION));
    SYST_RVR = HSI_HZ / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = 0x7u;
    for (;;) {
        uart_drain();
        uint8_t in[32];
        size_t n = 0;
        while (n < sizeof in && (USART2_SR & (1u << 5))) { /* RXNE */
            in[n++] = (uint8_t)USART2_DR;
        }
        if (n) {
            evdev_device_receive(&device, in, n);
        }
        if (ticks_due) {
            __asm__ volatile("cpsid i");
            ticks_due--;
            __asm__ volatile("cpsie i");
            evdev_device_tick(&device);
        }
    }
}
