/* Cortex-M4 start-up for the MPS2 AN386: the vector table, the reset handler (copy .data, zero .bss, run
 * main) and the memcpy/memset the compiler may call (the runtime links no C library). */
#include <stddef.h>
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;

#define STACK_PAINT 0xA5A5A5A5u
#define STACK_WATCHED 65536u /* bytes below the top of RAM painted at reset, to measure the stack's use */
int main(void);
void Reset_Handler(void);
void Default_Handler(void);

void *memcpy(void *dst, const void *src, size_t n)
{
    uint8_t *d = dst;
    const uint8_t *s = src;
    while (n--)
        *d++ = *s++;
    return dst;
}

void *memset(void *dst, int v, size_t n)
{
    uint8_t *d = dst;
    while (n--)
        *d++ = (uint8_t)v;
    return dst;
}

void Reset_Handler(void)
{
    uint32_t *s = &_sidata, *d = &_sdata;
    while (d < &_edata)
        *d++ = *s++;
    for (d = &_sbss; d < &_ebss;)
        *d++ = 0;
    /* paint the watched stack below this frame (a margin of 16 words) */
    for (d = (uint32_t *)((uintptr_t)&_estack - STACK_WATCHED); d < (uint32_t *)((uintptr_t)&s - 64u);)
        *d++ = STACK_PAINT;
    main();
    for (;;)
        ;
}

uint32_t sd_pil_stack_used(void)
{
    const uint32_t *d = (const uint32_t *)((uintptr_t)&_estack - STACK_WATCHED);
    while (*d == STACK_PAINT)
        ++d;
    return (uint32_t)((uintptr_t)&_estack - (uintptr_t)d);
}

/* SysTick (Armv7-M system control space) as a free-running 24-bit down-counter of processor clocks */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_MASK 0x00FFFFFFu

uint32_t sd_pil_clock(void)
{
    if (!(SYST_CSR & 1u)) {
        SYST_RVR = SYST_MASK;
        SYST_CVR = 0u;
        SYST_CSR = 5u; /* enabled, the processor clock, no interrupt */
    }
    return SYST_CVR;
}

uint32_t sd_pil_clock_since(uint32_t start) { return (start - SYST_CVR) & SYST_MASK; }

void Default_Handler(void)
{
    for (;;)
        ;
}

/* initial stack pointer, then the 15 system exceptions (no interrupts are enabled: the UART is polled) */
__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(uintptr_t)&_estack,
    Reset_Handler,
    Default_Handler, /* NMI */
    Default_Handler, /* HardFault */
    Default_Handler, /* MemManage */
    Default_Handler, /* BusFault */
    Default_Handler, /* UsageFault */
    0, 0, 0, 0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMonitor */
    0,
    Default_Handler, /* PendSV */
    Default_Handler, /* SysTick */
};
