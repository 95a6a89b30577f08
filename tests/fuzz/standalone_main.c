/* standalone_main.c - run a fuzz harness without libFuzzer.

       cc -fsanitize=address,undefined -I. tests/fuzz/fuzz_obj.c tests/fuzz/standalone_main.c -lm
       ./a.out [-m MUTATIONS] [-s SEED] FILE_OR_DIR...

   Every file (directories are read one level deep, in sorted order) is
   passed to LLVMFuzzerTestOneInput as is, then MUTATIONS (default 200)
   deterministic mutations of it: byte flips, insertions and deletions of
   bytes, digits and signs, swapped and duplicated lines, truncations, and
   splices with the other inputs.  The same seed gives the same inputs on
   every machine.  Used by tests/test_fuzz.sh when clang's libFuzzer is not
   available; a property violation aborts (the sanitizers report the rest).
   Prints "standalone: N inputs" at the end. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct buf { uint8_t *p; size_t n; } buf;

static buf *inputs;
static size_t num_inputs, cap_inputs;
static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static uint64_t rng(void)
{
    uint64_t x = rng_state;
    x ^= x >> 12; x ^= x << 25; x ^= x >> 27;
    rng_state = x;
    return x * 0x2545f4914f6cdd1dull;
}

static void add_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    buf b;
    long n;
    if (!f) { fprintf(stderr, "standalone: cannot open %s\n", path); exit(2); }
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    b.n = n > 0 ? (size_t)n : 0;
    b.p = (uint8_t *)malloc(b.n + 1);
    if (b.n && fread(b.p, 1, b.n, f) != b.n) { fprintf(stderr, "standalone: cannot read %s\n", path); exit(2); }
    fclose(f);
    if (num_inputs == cap_inputs) {
        cap_inputs = cap_inputs ? 2 * cap_inputs : 64;
        inputs = (buf *)realloc(inputs, cap_inputs * sizeof *inputs);
    }
    inputs[num_inputs++] = b;
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static void add_path(const char *path)
{
    struct stat st;
    DIR *d;
    struct dirent *e;
    char **names = NULL;
    size_t n = 0, cap = 0, i;
    if (stat(path, &st) != 0) { fprintf(stderr, "standalone: no such file %s\n", path); exit(2); }
    if (!S_ISDIR(st.st_mode)) { add_file(path); return; }
    d = opendir(path);
    while (d && (e = readdir(d)) != NULL) {
        char full[4096];
        if (e->d_name[0] == '.') continue;
        snprintf(full, sizeof full, "%s/%s", path, e->d_name);
        if (stat(full, &st) != 0 || !S_ISREG(st.st_mode)) continue;
        if (n == cap) { cap = cap ? 2 * cap : 64; names = (char **)realloc(names, cap * sizeof *names); }
        names[n] = (char *)malloc(strlen(full) + 1);
        strcpy(names[n++], full);
    }
    if (d) closedir(d);
    qsort(names, n, sizeof *names, cmp_str);
    for (i = 0; i < n; i++) { add_file(names[i]); free(names[i]); }
    free(names);
}

static const char tokens[][12] = { "0", "1", "-1", "2", "9", "4294967296", "1e308", "-0", "nan", "inf", "1e-300",
                                  " ", "/", "//", "\n", "\r\n", "#", "f ", "v ", "vt ", "OFF\n", "3 ", "\t", "." };

/* One mutation of src into dst (dst has room for src.n + 64). */
static size_t mutate(const buf *src, uint8_t *dst)
{
    size_t n = src->n, i, pos;
    int kind = (int)(rng() % 8), reps = 1 + (int)(rng() % 4), r;
    memcpy(dst, src->p, n);
    for (r = 0; r < reps; r++) {
        pos = n ? (size_t)(rng() % n) : 0;
        switch (kind) {
        case 0: if (n) dst[pos] ^= (uint8_t)(1u << (rng() % 8)); break;          /* bit flip */
        case 1: if (n) dst[pos] = (uint8_t)rng(); break;                          /* random byte */
        case 2: if (n) { memmove(dst + pos, dst + pos + 1, n - pos - 1); n--; } break;   /* delete */
        case 3: {                                                                 /* insert a token */
            const char *t = tokens[rng() % (sizeof tokens / sizeof tokens[0])];
            size_t k = strlen(t);
            if (n + k > src->n + 64) break;
            memmove(dst + pos + k, dst + pos, n - pos);
            memcpy(dst + pos, t, k);
            n += k;
            break;
        }
        case 4: if (n) { for (i = pos; i < n && dst[i] >= '0' && dst[i] <= '9'; i++) dst[i] = (uint8_t)('0' + rng() % 10); } break;
        case 5: n = pos; break;                                                   /* truncate */
        case 6: {                                                                 /* splice another input */
            const buf *o = &inputs[rng() % num_inputs];
            size_t k = o->n ? (size_t)(rng() % o->n) : 0, len = o->n - k;
            if (len > 64) len = 64;
            if (pos + len > src->n + 64) break;
            memcpy(dst + pos, o->p + k, len);
            if (pos + len > n) n = pos + len;
            break;
        }
        default: {                                                                /* duplicate a line */
            size_t a = pos, b;
            while (a > 0 && dst[a - 1] != '\n') a--;
            for (b = pos; b < n && dst[b] != '\n'; b++) {}
            if (b < n) b++;
            if (n + (b - a) > src->n + 64 || b - a == 0) break;
            memmove(dst + b + (b - a), dst + b, n - b);
            memcpy(dst + b, dst + a, b - a);
            n += b - a;
            break;
        }
        }
    }
    return n;
}

int main(int argc, char **argv)
{
    long mutations = 200, total = 0, m;
    size_t i, k;
    int a;
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "-m") && a + 1 < argc) mutations = atol(argv[++a]);
        else if (!strcmp(argv[a], "-s") && a + 1 < argc) rng_state = strtoull(argv[++a], NULL, 0) | 1;
        else add_path(argv[a]);
    }
    if (!num_inputs) { fprintf(stderr, "usage: %s [-m MUTATIONS] [-s SEED] FILE_OR_DIR...\n", argv[0]); return 2; }
    for (i = 0; i < num_inputs; i++) {
        uint8_t *copy = (uint8_t *)malloc(inputs[i].n ? inputs[i].n : 1);   /* exact size: overreads are caught */
        memcpy(copy, inputs[i].p, inputs[i].n);
        LLVMFuzzerTestOneInput(copy, inputs[i].n);
        free(copy);
        total++;
    }
    for (i = 0; i < num_inputs; i++) {
        uint8_t *tmp = (uint8_t *)malloc(inputs[i].n + 65);
        for (m = 0; m < mutations; m++) {
            size_t n = mutate(&inputs[i], tmp);
            uint8_t *copy = (uint8_t *)malloc(n ? n : 1);
            memcpy(copy, tmp, n);
            LLVMFuzzerTestOneInput(copy, n);
            free(copy);
            total++;
        }
        free(tmp);
    }
    for (k = 0; k < num_inputs; k++) free(inputs[k].p);
    free(inputs);
    printf("standalone: %ld inputs\n", total);
    return 0;
}
