/* bpt_triplets.h - compressed columns from (row, column, value) triplets,
   for the tests that build matrices by hand (tests/test_sparse.c,
   tests/test_tutte.c).  It was the library's own assembly of the L-BFGS
   preconditioner's Laplacian until that was assembled straight into its
   columns on the threads (bp__laplacian); here it is the independent
   reference that assembly is compared with.  Include after bijparam.h
   with BP_IMPLEMENTATION (it uses the header's allocator and bp__sparse). */
#ifndef BPT_TRIPLETS_H
#define BPT_TRIPLETS_H

typedef struct bpt_trip { uint32_t i, j; double v; } bpt_trip;

/* Compressed columns from triplets (duplicates summed, in input order).
   A counting sort by column, then each column (a vertex's neighbours,
   a few dozen entries) by row with a stable insertion sort: linear time on
   a mesh, where a comparison sort of all triplets was the set-up's largest
   serial cost.  The order equals the stable sort by (column, row).  `t` is
   only read. */
static int bpt_from_triplets(const bp_allocator *a, uint32_t n, bpt_trip *t, size_t nt, bp__sparse *A)
{
    size_t k, w = 0, m;
    uint32_t j, *ord = (uint32_t *)bp__alloc_array(a, nt ? nt : 1, sizeof(uint32_t));
    A->n = n;
    A->colp = (uint32_t *)bp__calloc_array(a, (size_t)n + 2, sizeof(uint32_t));
    if (!ord || !A->colp || nt > 0xfffffff0u) { bp__free(a, ord); return 0; }
    for (k = 0; k < nt; k++) A->colp[t[k].j + 2]++;
    for (j = 0; j < n; j++) A->colp[j + 2] += A->colp[j + 1];
    for (k = 0; k < nt; k++) ord[A->colp[t[k].j + 1]++] = (uint32_t)k;   /* column j: [colp[j], colp[j+1]) */
    for (j = 0; j < n; j++)
        for (k = A->colp[j] + 1; k < A->colp[j + 1]; k++) {
            uint32_t o = ord[k];
            for (m = k; m > A->colp[j] && t[ord[m - 1]].i > t[o].i; m--) ord[m] = ord[m - 1];
            ord[m] = o;
        }
    for (k = 0; k < nt; k++)                       /* distinct entries */
        if (k == 0 || t[ord[k]].j != t[ord[k - 1]].j || t[ord[k]].i != t[ord[k - 1]].i) w++;
    A->row = (uint32_t *)bp__alloc_array(a, w ? w : 1, sizeof(uint32_t));
    A->val = (double *)bp__alloc_array(a, w ? w : 1, sizeof(double));
    if (!A->row || !A->val) { bp__free(a, ord); return 0; }
    w = 0;
    for (j = 0; j < n; j++) {
        size_t c0 = w, k1 = A->colp[j + 1];
        for (k = A->colp[j]; k < k1; k++) {
            const bpt_trip *e = &t[ord[k]];
            if (w > c0 && A->row[w - 1] == e->i) A->val[w - 1] += e->v;
            else { A->row[w] = e->i; A->val[w++] = e->v; }
        }
        A->colp[j] = (uint32_t)c0;
    }
    A->colp[n] = (uint32_t)w;
    bp__free(a, ord);
    return 1;
}

#endif
