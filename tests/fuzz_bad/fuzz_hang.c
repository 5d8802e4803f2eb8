/* Must fail `make fuzz`: spins on any input of two bytes or more (the per-input timeout). */
#include <stdint.h>
#include <stddef.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    volatile unsigned spin = data && size ? data[0] : 0;
    while (size >= 2) spin++;
    return (int)(spin & 0);
}
