/* fuzz_off.c - libFuzzer harness for bp_parse_off.

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
    char *text = fuzz_copy(data, size);
    bp_mesh m;
    bp_error err;
    bp_status st;
    memset(&m, 0xAB, sizeof m);
    st = bp_parse_off(text, size, &m, NULL, &err);
    free(text);
    if (st == BP_OK) {
        bp_atlas at;
        fuzz_check_mesh(&m);
        st = bp_atlas_build(&at, &m, NULL, &err);
        if (st != BP_OK && st != BP_ERR_CHARTS_FAILED) {
            fuzz_check_error(st, &err);
            if (at.charts || at.num_charts) fuzz_fail("failed bp_atlas_build left charts");
        }
        bp_atlas_free(&at);
        bp_mesh_free(&m, NULL);
    } else {
        fuzz_check_error(st, &err);
        if (!fuzz_mesh_all_null(&m)) fuzz_fail("failed parse left the mesh non-zero");
    }
    return 0;
}
