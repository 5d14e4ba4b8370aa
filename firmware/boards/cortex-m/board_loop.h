/* What every board here shares: the transmit ring behind evdev_board's
 * `write` (writing never waits), the SysTick count of ticks due, and the
 * main loop (bytes from the UART to the core, the ring to the UART, one
 * core tick per SysTick). A board sets up its clock, UART and DAC, fills
 * an evdev_board with board_loop_write as `write`, and calls board_loop_run.
 * The board's SysTick fires at 1 kHz; SysTick_Handler is defined here. */
#ifndef BOARD_LOOP_H
#define BOARD_LOOP_H

#include "../../core/evdev.h"

/* The board's UART, polled. */
typedef struct {
    int (*rx_ready)(void);       /* a received byte waits */
    uint8_t (*rx_byte)(void);    /* takes it */
    int (*tx_ready)(void);       /* the UART takes a byte now */
    void (*tx_byte)(uint8_t b);  /* gives it one */
    /* Called after each tick (a board's logs); NULL for none. */
    void (*after_tick)(const evdev_device *d);
} board_uart;

/* evdev_board.write: queues the bytes, or drops the frame whole (counted)
 * when the ring is full. */
void board_loop_write(void *ctx, const uint8_t *p, size_t n);

/* Frames dropped because the transmit ring was full. */
uint32_t board_loop_dropped(void);

/* Starts SysTick at clock_hz / 1000 and runs the device for ever. */
void board_loop_run(evdev_device *d, const board_uart *u, uint32_t clock_hz);

#endif
