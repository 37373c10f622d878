/* libFuzzer harness: plant graphs in the paper format (see fuzz_plant.h). */
#include "fuzz_plant.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return phc_fuzz_plant(data, size, PHC_PLANT_FORMAT_PAPER, "plant.txt");
}
