// Entry point of seasense_bench: every tests/bench/*.cpp registers its benchmarks here.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
