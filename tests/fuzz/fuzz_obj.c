/* fuzz_obj.c - libFuzzer harness for bp_parse_obj.

   Properties: never crash or read past the input; BP_OK gives a consistent
   mesh (indices in range, finite numbers, ordered triangle_line and
   triangle_face) that bp_mesh_free releases; a failure leaves the mesh
   zeroed (nothing allocated: LeakSanitizer) and names its line.  Every
   accepted mesh also goes through bp_atlas_build, which must either build
   or fail with a message, and never crash. */
#ifndef BP_FUZZ_EXTERNAL_IMPL  /* else bijparam.h is compiled once, separately */
#define BP_IMPLEMENTATION
#endif
#include "bijparam.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_parser(data, size, bp_parse_obj);
}
