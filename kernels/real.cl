/* real.cl: the scalar and vector types every kernel piece is written in.
 * -D REAL_DOUBLE builds the double-precision variant (needs cl_khr_fp64);
 * the default is float, which is what GPUs run fast. */
#ifdef REAL_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double real;
typedef double4 real4;
typedef double3 real3;
#define REAL_MAX DBL_MAX
#define REAL_MIN DBL_MIN
#else
typedef float real;
typedef float4 real4;
typedef float3 real3;
#define REAL_MAX FLT_MAX
#define REAL_MIN FLT_MIN
#endif

/* The scene's fractal constants, passed by value to every piece. */
typedef struct {
    real4 c;         /* Julia constant */
    real bailout2;   /* escape radius squared */
    real epsilon;    /* distance-estimate hit threshold */
    int max_iter;
#ifdef COUNT_ITERATIONS
    __global int *count;   /* this ray's iterations of f (benchmarks/throughput.py); 0: none */
#endif
} julia_params;

/* -D COUNT_ITERATIONS (benchmarks only): the march counts every iteration of f its set
 * tests make, per ray, through an extra kernel argument; otherwise these are empty. */
#ifdef COUNT_ITERATIONS
#define COUNT_ITER(jp, n) do { if ((jp).count) *(jp).count += (n); } while (0)
#define COUNTER_ARG , __global int *iter_count
#define COUNTER_INIT(i) , iter_count + (i)
#else
#define COUNT_ITER(jp, n)
#define COUNTER_ARG
#define COUNTER_INIT(i)
#endif

/* Pixel status codes written by the march kernel (mirrored in reference.py). */
#define STATUS_MISS 0
#define STATUS_HIT 1
#define STATUS_CAPPED 2   /* the step cap ended the march before a hit or the far plane */

/* Guard flags (nothing clamped without being counted).  The normals kernels
 * write them into the w component of the normal buffer, otherwise 0, and the host
 * counts the pixels each fired on (RenderResult.guards; mirrored in reference.py). */
#define GUARD_NORMAL_FALLBACK 1   /* degenerate or non-finite normal replaced by the view axis */
#define GUARD_JACOBIAN_TINY 2     /* Jacobian iteration stopped: q_n about to underflow (c ~ 0) */
/* The march kernel writes its own flags buffer (same counting on the host). */
#define GUARD_ULP_STEP 4          /* de: a step below the spacing of t was raised to one ulp */
#define GUARD_SHELL_MISS 8        /* de: came within epsilon by the estimate, never inside: a miss */
