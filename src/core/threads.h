/* The number of worker threads the kernels use (OpenMP when built with it, else 1). */
#ifndef GRAINLAB_CORE_THREADS_H
#define GRAINLAB_CORE_THREADS_H

int threads_get(void);

/* n >= 1; values above the number of processors are allowed (oversubscription). */
void threads_set(int n);

/* Processors available to this process. */
int threads_available(void);

#endif
