/* The PIL program on the host: the link on stdin and stdout (a pipe in the tests). */
#include <stdio.h>

#include "sd_pil.h"

void sd_pil_write(const uint8_t *data, size_t n)
{
    fwrite(data, 1, n, stdout);
    fflush(stdout);
}

uint32_t sd_pil_stack_used(void) { return 0xFFFFFFFFu; }

uint32_t sd_pil_clock(void) { return 0u; }

uint32_t sd_pil_clock_since(uint32_t start)
{
    (void)start;
    return 0xFFFFFFFFu; /* no cycle clock on the host */
}

int main(void)
{
    static sd_pil pil;
    int c;
    sd_pil_init(&pil);
    while ((c = getchar()) != EOF)
        sd_pil_byte(&pil, (uint8_t)c);
    return 0;
}
