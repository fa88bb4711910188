/* The PIL program's link over Arm semihosting (BKPT 0xAB): the debugger or emulator reads and writes the host's
 * console for the core, a buffer a call. Under QEMU (-semihosting-config enable=on,target=native, no chardev)
 * the console is QEMU's own standard input and output, read with a blocking read(): a frame crosses in one call
 * instead of one UART byte a trip through QEMU's main loop, and the core waits without spinning. A board runs
 * it only under a debug probe with semihosting enabled (without one, BKPT faults). The end of the input (the
 * host closed the link) or a failed read ends the program (SYS_EXIT). */
#include "sd_pil.h"

#define SYS_OPEN 0x01
#define SYS_WRITE 0x05
#define SYS_READ 0x06
#define SYS_EXIT 0x18
#define OPEN_READ 0u  /* fopen's "r" */
#define OPEN_WRITE 4u /* fopen's "w" */
#define APPLICATION_EXIT 0x20026u
#define CHUNK 256u

/* op in r0, its argument (a parameter block's address, or SYS_EXIT's reason) in r1; the result in r0 */
static uint32_t semihost(uint32_t op, uintptr_t arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register uintptr_t r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static uint32_t console(uint32_t mode)
{
    static const char tt[] = ":tt";
    const uint32_t args[3] = {(uint32_t)(uintptr_t)tt, mode, sizeof tt - 1u};
    return semihost(SYS_OPEN, (uintptr_t)args);
}

static uint32_t out_handle;

void sd_pil_write(const uint8_t *data, size_t n)
{
    const uint32_t args[3] = {out_handle, (uint32_t)(uintptr_t)data, (uint32_t)n};
    (void)semihost(SYS_WRITE, (uintptr_t)args);
}

static sd_pil pil;
static uint8_t chunk[CHUNK];

int main(void)
{
    const uint32_t in_handle = console(OPEN_READ);
    const uint32_t read_args[3] = {in_handle, (uint32_t)(uintptr_t)chunk, CHUNK};
    out_handle = console(OPEN_WRITE);
    sd_pil_init(&pil);
    for (;;) {
        uint32_t n = CHUNK - semihost(SYS_READ, (uintptr_t)read_args), i; /* SYS_READ returns the bytes not read */
        if (n == 0u || n > CHUNK)                                         /* the end of the input, or an error */
            (void)semihost(SYS_EXIT, APPLICATION_EXIT);
        for (i = 0; i < n; ++i)
            sd_pil_byte(&pil, chunk[i]);
    }
}
