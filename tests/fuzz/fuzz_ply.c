/* fuzz_ply.c - libFuzzer harness for bp_parse_ply: the properties of
   fuzz_obj.c (fuzz_common.h's fuzz_parser checks them), on PLY data
   (ASCII and binary headers; the seeds hold both). */
#ifndef BP_FUZZ_EXTERNAL_IMPL  /* else bijparam.h is compiled once, separately */
#define BP_IMPLEMENTATION
#endif
#include "bijparam.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_parser(data, size, bp_parse_ply);
}
