/* Thread count: a thin layer over OpenMP so kernels and bindings never include omp.h. */
#include "core/threads.h"

#ifdef GRAINLAB_HAVE_OPENMP
#include <omp.h>
int threads_get(void) { return omp_get_max_threads(); }
void threads_set(int n) { omp_set_num_threads(n > 0 ? n : 1); }
int threads_available(void) { return omp_get_num_procs(); }
#else
int threads_get(void) { return 1; }
void threads_set(int n) { (void)n; }
int threads_available(void) { return 1; }
#endif
