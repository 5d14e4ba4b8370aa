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
#include "../cortex-m/board_loop.h"

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

#define HSI_HZ 16000000u
#define BAUD 460800u

static int rx_ready(void) { return (USART2_SR & (1u << 5)) != 0; } /* RXNE */
static uint8_t rx_byte(void) { return (uint8_t)USART2_DR; }
static int tx_ready(void) { return (USART2_SR & (1u << 7)) != 0; } /* TXE */
static void tx_byte(uint8_t b) { USART2_DR = b; }

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
    static evdev_device device;
    static const evdev_board board = {0, board_loop_write, dac, 0, 0, 0, 0};
    static const board_uart uart = {rx_ready, rx_byte, tx_ready, tx_byte, 0};
    evdev_device_init(&device, &board, evdev_default_config(EVDEV_CAP_ACTUATION));
    board_loop_run(&device, &uart, HSI_HZ);
    return 0;
}
