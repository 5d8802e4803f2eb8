/* Must fail `make fuzz`: aborts on any input of two bytes or more (tests/fuzz_fails.sh). */
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    (void)data;
    if (size >= 2) abort();
    return 0;
}
