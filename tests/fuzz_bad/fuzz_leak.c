/* Must fail `make fuzz`: loses a block on any input of two bytes or more (LeakSanitizer). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static void *volatile sink;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size >= 2) {
        char *p = (char *)malloc(size);
        memcpy(p, data, size);
        sink = p;
        sink = NULL; /* the block is unreachable from here on */
    }
    return 0;
}
