/* The PIL program on an STM32F405/F407: USART2 on PA2 (TX) and PA3 (RX), alternate function 7, 115200 baud
 * 8N1 from the reset clock (the 16 MHz HSI oscillator, APB1 undivided), polled, carrying the link. On the
 * STM32F4 Discovery connect a 3.3 V USB-serial adapter to PA2/PA3 and GND. */
#include "sd_pil.h"

#define RCC_AHB1ENR (*(volatile uint32_t *)0x40023830u)
#define RCC_APB1ENR (*(volatile uint32_t *)0x40023840u)
#define GPIOA_MODER (*(volatile uint32_t *)0x40020000u)
#define GPIOA_AFRL (*(volatile uint32_t *)0x40020020u)
#define USART2_SR (*(volatile uint32_t *)0x40004400u)
#define USART2_DR (*(volatile uint32_t *)0x40004404u)
#define USART2_BRR (*(volatile uint32_t *)0x40004408u)
#define USART2_CR1 (*(volatile uint32_t *)0x4000440Cu)
#define SR_RXNE (1u << 5)
#define SR_TXE (1u << 7)
#define APB1_HZ 16000000u /* HSI after reset: SYSCLK = AHB = APB1 = 16 MHz */
#define BAUD 115200u

static void usart_init(void)
{
    RCC_AHB1ENR |= 1u;        /* GPIOA */
    RCC_APB1ENR |= 1u << 17;  /* USART2 */
    GPIOA_MODER = (GPIOA_MODER & ~(0xFu << 4)) | (0xAu << 4); /* PA2, PA3: alternate function */
    GPIOA_AFRL = (GPIOA_AFRL & ~(0xFFu << 8)) | (0x77u << 8);  /* AF7: USART2 */
    USART2_BRR = (APB1_HZ + BAUD / 2u) / BAUD;                 /* 16x oversampling: 139 = 0x8B, 115108 baud */
    USART2_CR1 = (1u << 13) | (1u << 3) | (1u << 2);           /* UE, TE, RE */
}

static uint8_t usart_getc(void)
{
    while (!(USART2_SR & SR_RXNE))
        ;
    return (uint8_t)USART2_DR;
}

void sd_pil_write(const uint8_t *data, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        while (!(USART2_SR & SR_TXE))
            ;
        USART2_DR = data[i];
    }
}

static sd_pil pil;

int main(void)
{
    usart_init();
    sd_pil_init(&pil);
    for (;;)
        sd_pil_byte(&pil, usart_getc());
}
