/* Start-up for a Cortex-M3/M4 board: the vector table, the reset handler
 * (copy .data, zero .bss, call main) and a fault handler that stops. The
 * board's linker script provides the symbols; the board file provides
 * main and SysTick_Handler. */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss;
int main(void);
void SysTick_Handler(void);

void Reset_Handler(void);
void Fault_Handler(void);

void Fault_Handler(void) {
    for (;;) {
    }
}

void Reset_Handler(void) {
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
    (void)main();
    for (;;) {
    }
}

/* Core exceptions from the reset vector on (the initial stack pointer
 * before it is written by sections.ld); the boards here use no peripheral
 * interrupt. */
__attribute__((section(".vectors"), used)) static void (*const vectors[15])(void) = {
    Reset_Handler,
    Fault_Handler, /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0, 0, 0, 0,
    Fault_Handler, /* SVCall */
    Fault_Handler, /* DebugMon */
    0,
    Fault_Handler, /* PendSV */
    SysTick_Handler,
};
