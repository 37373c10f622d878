/* The photos module's entry point (measurements/photo_module_internal.h):
 * the table of this module's OpenCV functions, for libphytocal to call.
 * Compiled into phytocal_photo.so only, with the other photo_*_bridge.cc. */
#include "measurements/photo_module_internal.h"

#define PHC_PHOTO_MODULE_ENTRY_VALUE(name, params, args) name,
static const phc_photo_module_table phc_photo_module = {PHC_PHOTO_MODULE_FUNCTIONS(PHC_PHOTO_MODULE_ENTRY_VALUE)};

extern "C" const void *phc_photo_module_entry(int abi)
{
    return abi == PHC_PHOTO_MODULE_ABI ? &phc_photo_module : nullptr;
}
