/* The PIL program on the MPS2 AN386: the CMSDK APB UART0 (0x40004000), polled, carrying the link. */
#include "sd_pil.h"

#define UART0_BASE 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0_BASE + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0_BASE + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0_BASE + 0x08u))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0_BASE + 0x10u))
#define STATE_TX_FULL 1u
#define STATE_RX_FULL 2u
#define CTRL_TX_EN 1u
#define CTRL_RX_EN 2u

static void uart_init(void)
{
    UART_BAUDDIV = 16u; /* the smallest divisor the CMSDK UART takes; the emulated line is not timed */
    UART_CTRL = CTRL_TX_EN | CTRL_RX_EN;
}

static uint8_t uart_getc(void)
{
    while (!(UART_STATE & STATE_RX_FULL))
        ;
    return (uint8_t)UART_DATA;
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
