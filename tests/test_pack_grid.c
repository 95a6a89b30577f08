/* test_pack_grid.c - test_pack.c again, with the packer's search on a grid
   of at most 40 cells a side (BP__PACK_GRID, >>pack step 3): every atlas
   above 40 texels (all of test_pack.c's but one) is then searched on
   cells of 2 to 8 texels, and the same brute-force checks must hold on
   the final coordinates -- padding between charts, the border, every
   triangle positive, no overlap, one texel density, the utilization, the
   same bits on 1 and 2 threads. */
#define BP__PACK_GRID 40
#include "test_pack.c"
