/* The floor under a frame's resolve, shading and store: the time this machine takes to
 * write a frame's three planes (colour, depth, triangle id: 4 bytes a pixel each) with
 * non-temporal stores, as the resolve and the shading write them, and nothing else.
 *
 *   cc -O2 -mavx2 -pthread scripts/write-floor.c -o /tmp/write-floor
 *   /tmp/write-floor 1920 1080 2      # width, height, threads
 *
 * Prints the best of 50 writes in ms. `continuum compare`'s frame share target (resolve +
 * shading + store at most 15% of a frame) cannot be met by a frame faster than this
 * floor divided by 0.15, however cheap the shading. */
#include <immintrin.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static float *planes[3];
static size_t pixels;
static int threads;

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static void *write_share(void *arg) {
    size_t id = (size_t)arg;
    size_t lo = (pixels * id / threads) & ~(size_t)7, hi = (pixels * (id + 1) / threads) & ~(size_t)7;
    __m256 v = _mm256_set1_ps(1.0f);
    for (int k = 0; k < 3; k++)
        for (size_t i = lo; i < hi; i += 8) _mm256_stream_ps(planes[k] + i, v);
    _mm_sfence();
    return NULL;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: %s WIDTH HEIGHT THREADS\n", argv[0]);
        return 2;
    }
    pixels = (size_t)atoi(argv[1]) * (size_t)atoi(argv[2]);
    threads = atoi(argv[3]);
    if (pixels == 0 || threads < 1 || threads > 64) {
        fprintf(stderr, "WIDTH and HEIGHT must be positive, THREADS in 1..=64\n");
        return 2;
    }
    for (int k = 0; k < 3; k++) {
        planes[k] = aligned_alloc(64, (pixels * 4 + 63) & ~(size_t)63);
        for (size_t i = 0; i < pixels; i++) planes[k][i] = 0.0f; /* fault the pages in */
    }
    double best = 1e9;
    for (int r = 0; r < 50; r++) {
        pthread_t t[64];
        double t0 = now();
        for (int i = 0; i < threads; i++) pthread_create(&t[i], NULL, write_share, (void *)(size_t)i);
        for (int i = 0; i < threads; i++) pthread_join(t[i], NULL);
        double spent = now() - t0;
        if (spent < best) best = spent;
    }
    printf("%zu pixels, 3 planes (%.1f MB), %d threads: %.3f ms (best of 50), %.1f GB/s\n", pixels,
           pixels * 12 / 1e6, threads, best * 1e3, pixels * 12 / best / 1e9);
    return 0;
}
