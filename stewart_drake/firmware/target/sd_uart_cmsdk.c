/* The PIL program on the MPS2 AN386: the CMSDK APB UART0 (0x40004000) carrying the link, read by waiting for
 * its receive interrupt (IRQ 0) with interrupts masked: WFI wakes on the pending interrupt, none is taken (the
 * vector table has no IRQ entries). The core sleeps between bytes instead of polling the UART: under QEMU the
 * emulator's I/O thread then runs without contending with the busy core. */
#include "sd_pil.h"

#define UART0_BASE 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0_BASE + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0_BASE + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0_BASE + 0x08u))
#define UART_INTSTATUS (*(volatile uint32_t *)(UART0_BASE + 0x0Cu))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0_BASE + 0x10u))
#define NVIC_ISER0 (*(volatile uint32_t *)0xE000E100u)
#define NVIC_ICPR0 (*(volatile uint32_t *)0xE000E280u)
#define UART0_RX_IRQ 0u
#define STATE_TX_FULL 1u
#define STATE_RX_FULL 2u
#define CTRL_TX_EN 1u
#define CTRL_RX_EN 2u
#define CTRL_RX_INT_EN 8u
#define INT_RX 2u

static void uart_init(void)
{
    UART_BAUDDIV = 16u; /* the smallest divisor the CMSDK UART takes; the emulated line is not timed */
    __asm volatile("cpsid i" ::: "memory"); /* PRIMASK: pending interrupts wake WFI, none is taken */
    UART_CTRL = CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_INT_EN;
    NVIC_ISER0 = 1u << UART0_RX_IRQ;
}

static uint8_t uart_getc(void)
{
    for (;;) {
        UART_INTSTATUS = INT_RX; /* clear the UART's and then the NVIC's pending receive interrupt */
        NVIC_ICPR0 = 1u << UART0_RX_IRQ;
        if (UART_STATE & STATE_RX_FULL)
            return (uint8_t)UART_DATA;
        __asm volatile("wfi" ::: "memory"); /* a byte that came since the test above left the interrupt pending */
    }
}

void sd_pil_write(const uint8_t *data, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        while (UART_STATE & STATE_TX_FULL)
            ;
        UART_DATA = data[i];
    }
}

static sd_pil pil;

int main(void)
{
    uart_init();
    sd_pil_init(&pil);
    for (;;)
        sd_pil_byte(&pil, uart_getc());
}
