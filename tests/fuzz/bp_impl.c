/* bp_impl.c - the implementation of bijparam.h as its own translation unit,
   so that tests/test_fuzz.sh compiles the (large) header once per compiler
   and links every harness (built with -DBP_FUZZ_EXTERNAL_IMPL) against it. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
