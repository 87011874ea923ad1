/* common/lanes.cl: the scalar and vector types every kernel piece is written in.
 * -D REAL_DOUBLE builds the double-precision variant (needs cl_khr_fp64);
 * the default is float, which is what GPUs run fast. */
#ifdef REAL_DOUBLE
#if !defined(DEV_FP64) && defined(DEV_CL_C)
#error "double precision (REAL_DOUBLE) on a device without cl_khr_fp64"
#endif
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double real;
typedef double4 real4;
typedef double3 real3;
typedef double2 real2;
#define REAL_MAX DBL_MAX
#define REAL_MIN DBL_MIN
#else
typedef float real;
typedef float4 real4;
typedef float3 real3;
typedef float2 real2;
#define REAL_MAX FLT_MAX
#define REAL_MIN FLT_MIN
#endif

/* The scene's fractal constants, passed by value to every piece. */
#ifndef LANES
#define LANES 1      /* rays per work-item (see "Lanes" below) */
#endif

typedef struct {
    real4 c;         /* Julia constant */
    real bailout2;   /* escape radius squared */
    real epsilon;    /* distance-estimate hit threshold */
    int max_iter;
#if defined(COUNT_ITERATIONS) && LANES == 1
    __global int *count;   /* this ray's iterations of f (benchmarks/speed/throughput.py); 0: none */
#endif
} julia_params;

/* -D COUNT_ITERATIONS (benchmarks only; one ray per work-item): the march counts every
 * iteration of f its set tests make, per ray, through an extra kernel argument; otherwise
 * these are empty. */
#if defined(COUNT_ITERATIONS) && LANES == 1
#define COUNT_ITER(jp, n) do { if ((jp).count) *(jp).count += (n); } while (0)
#define COUNTER_ARG , __global int *iter_count
#define COUNTER_INIT(i) , iter_count + (i)
#define COUNTER_NONE , 0    /* a kernel without the counter argument counts nothing */
#else
#define COUNT_ITER(jp, n)
#define COUNTER_ARG
#define COUNTER_INIT(i)
#define COUNTER_NONE
#endif

/* -D CLIP: the scene's up to 4 half-spaces clip_n[k] . p <= clip_off[k] (scene.Clip), the
 * arguments of the kernels that cut the set (march/march.cl, mesh/mesh.cl), handed on to their
 * helpers by CLIP_PASS; CLIP_NORMAL(k) and CLIP_OFFSET(k) are plane k's (march/clip.cl too). */
#ifdef CLIP
#define CLIP_ARGS , const int n_clip, const real4 clip_n0, const real4 clip_n1, const real4 clip_n2, \
                  const real4 clip_n3, const real4 clip_off
#define CLIP_PASS , n_clip, clip_n0, clip_n1, clip_n2, clip_n3, clip_off
#else
#define CLIP_ARGS
#define CLIP_PASS
#endif
#define CLIP_NORMAL(k) ((k) == 0 ? clip_n0 : (k) == 1 ? clip_n1 : (k) == 2 ? clip_n2 : clip_n3)
#define CLIP_OFFSET(k) ((k) == 0 ? clip_off.x : (k) == 1 ? clip_off.y : (k) == 2 ? clip_off.z : clip_off.w)

/* Dot products and unit vectors of one work-item's vectors, written out.  Intel's CPU
 * compiler runs a kernel of one ray per work-item 16 work-items at a time (AVX-512), but not
 * where it calls the builtin dot, length, normalize or cross: then its build log says "was
 * not vectorized" and it runs one pixel at a time (the shade kernel took 2.1x its time so).
 * UNIT3 takes ``fallback`` where a has no direction (|a|^2 is 0, or not finite). */
#define DOT3(a, b) ((a).x * (b).x + (a).y * (b).y + (a).z * (b).z)
#define DOT4(a, b) ((a).x * (b).x + (a).y * (b).y + (a).z * (b).z + (a).w * (b).w)
inline float3 UNIT3(float3 a, float3 fallback)
{
    float aa = DOT3(a, a);
    return aa > 0.0f && aa <= FLT_MAX ? a * rsqrt(aa) : fallback;
}

/* HITS_ONLY(i, n_items, status, on_miss): the start of every kernel of one pixel per
 * work-item: past the end it returns, on a miss (status[i] not STATUS_HIT) it runs the
 * statement on_miss and returns.  Intel's CPU compiler runs 16 work-items of such a kernel in
 * the lanes of one vector (above), and a branch on the pixel as both sides in every lane, so
 * the vectors of misses did the hits' work: first, a sub-group (those lanes) without a hit
 * returns at once (the shade kernel took 0.6x its time on the default scene at max_iter 20,
 * the gradient normals 0.3x).  Every work-item of a sub-group must reach sub_group_any,
 * those past the end too.  The vector's test stays apart from the lane's own: joined in one
 * condition, the compiler made it a lane branch again (the shade kernel 2.15 ms, not 1.05).
 * Without sub-groups, each work-item branches alone, as GPUs do anyway.  DEV_SUBGROUPS is
 * the device's answer, not the compiler's macro (pyjulia4d/opencl/capabilities.py: a
 * compiler may define cl_intel_subgroups and not link sub_group_any). */
#if defined(DEV_SUBGROUPS)
#ifdef DEV_KHR_SUBGROUPS
#pragma OPENCL EXTENSION cl_khr_subgroups : enable
#endif
#define GROUP_ANY(x) sub_group_any(x)
#else
#define GROUP_ANY(x) (x)
#endif
#define HITS_ONLY(i, n_items, status, on_miss) do { \
        int hit_ = (i) < (size_t)(n_items) && (status)[i] == STATUS_HIT; \
        if (!GROUP_ANY(hit_)) { \
            if ((i) < (size_t)(n_items)) \
                on_miss; \
            return; \
        } \
        if ((i) >= (size_t)(n_items)) \
            return; \
        if (!hit_) { \
            on_miss; \
            return; \
        } \
    } while (0)

/* Pixel status codes and guard flags: common/codes.cl (read by pyjulia4d/pipeline/codes.py too). */

/* Lanes: the per-ray code is written once on these types.  LANES = 1 (the default) is one
 * ray per work-item, quat = real4 (GPUs, and the normals and shading everywhere); LANES = N
 * (-D LANES=8, 16) is a packet of N neighbouring rays per work-item in structure-of-arrays
 * form, quat = four realN, so a CPU runs the N rays in its vector lanes (PoCL does not
 * vectorise a data-dependent loop across work-items).  A lane mask is what a comparison
 * gives: 1 / 0 for one lane, -1 / 0 per lane for N; finished lanes are frozen by L_SEL and
 * loops run while L_ANY lane is live.  A comparison of doubleN gives longN, so in double
 * precision packets (-D REAL_DOUBLE with LANES = N) lmask is longN; its lanes are mask_t
 * (int, or long there) and the int exponents of ldexp / frexp are lint, converted with
 * L_INT / L_MASK.  Counts and codes live in lmask either way. */
#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
/* A packet is a block of BLOCK_W x BLOCK_H neighbouring pixels (-D from build.py's
 * PACKET_BLOCKS; a row of LANES pixels if not given). */
#ifndef BLOCK_W
#define BLOCK_W LANES
#define BLOCK_H 1
#endif
#if LANES == 1
typedef real lreal;
typedef int lmask;
typedef int mask_t;
typedef int lint;
#define L_INT(m) (m)
#define L_MASK(i) (i)
typedef real4 quat;
#define L_ANY(m) (m)
#define L_SEL(a, b, m) ((m) ? (b) : (a))
#define QUAT(a, b, c, d) ((real4)((a), (b), (c), (d)))
#define QNORM2(q) DOT4((q), (q))
#define QADD_UNIFORM(q, v) ((q) + (v))
#define QADD(a, b) ((a) + (b))
#define QSEL(a, b, m) ((m) ? (b) : (a))
#define QRAY(o, d, t) ((o) + (t) * (d))
#define QDOT(a, b) DOT4((a), (b))
#define QLEN(q) sqrt(DOT4((q), (q)))
#define QSCALE(s, q) ((s) * (q))
#define QDOT_UNIFORM(q, v) DOT4((q), (v))
#define L_TRUE 1
#define convert_lreal(m) ((real)(m))
#else
#ifdef REAL_DOUBLE
#define LREAL_TYPE CAT(double, LANES)   /* the hint below takes a built-in type */
typedef LREAL_TYPE lreal;
typedef CAT(long, LANES) lmask;
typedef long mask_t;
#define L_INT(m) CAT(convert_int, LANES)(m)
#define L_MASK(i) CAT(convert_long, LANES)(i)
#define convert_lreal(m) CAT(convert_double, LANES)(m)
#else
#define LREAL_TYPE CAT(float, LANES)
typedef LREAL_TYPE lreal;
typedef CAT(int, LANES) lmask;
typedef int mask_t;
#define L_INT(m) (m)
#define L_MASK(i) (i)
#define convert_lreal(m) CAT(convert_float, LANES)(m)
#endif
typedef CAT(int, LANES) lint;
typedef struct { lreal x, y, z, w; } quat;
#define L_ANY(m) any(m)
#define L_SEL(a, b, m) select((a), (b), (m))
inline quat quat_make(lreal a, lreal b, lreal c, lreal d) { quat q = {a, b, c, d}; return q; }
#define QUAT(a, b, c, d) quat_make((a), (b), (c), (d))
inline lreal QNORM2(quat q) { return q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w; }
inline quat QADD_UNIFORM(quat q, real4 v) { return QUAT(q.x + v.x, q.y + v.y, q.z + v.z, q.w + v.w); }
inline quat QADD(quat a, quat b) { return QUAT(a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w); }
inline quat QRAY(quat o, quat d, lreal t)
{
    return QUAT(o.x + t * d.x, o.y + t * d.y, o.z + t * d.z, o.w + t * d.w);
}
inline lreal QDOT(quat a, quat b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
inline lreal QDOT_UNIFORM(quat a, real4 v) { return a.x * v.x + a.y * v.y + a.z * v.z + a.w * v.w; }
inline lreal QLEN(quat q) { return sqrt(QNORM2(q)); }
inline quat QSCALE(lreal s, quat q) { return QUAT(s * q.x, s * q.y, s * q.z, s * q.w); }
#define L_TRUE (-1)
inline quat QSEL(quat a, quat b, lmask m)
{
    return QUAT(select(a.x, b.x, m), select(a.y, b.y, m), select(a.z, b.z, m), select(a.w, b.w, m));
}
#endif

/* Lane k of a packet, read or written: LANE of an lreal (an lvalue), MASK_LANE of an lmask,
 * LANE_QUAT of a quat as a
 * real4, SET_LANE_QUAT to store one - the one place the packet's structure-of-arrays layout
 * (its vectors' lanes addressed as an array of reals) is spelled out.  With one ray per
 * work-item lane 0 is the value itself. */
#define LANE(v, k) (((real *)&(v))[k])
#define MASK_LANE(m, k) (((mask_t *)&(m))[k])
#define LANE_QUAT(q, k) ((real4)(LANE((q).x, k), LANE((q).y, k), LANE((q).z, k), LANE((q).w, k)))
#define SET_LANE_QUAT(q, k, v) do { \
        real4 lane_q_ = (v); \
        LANE((q).x, k) = lane_q_.x; LANE((q).y, k) = lane_q_.y; LANE((q).z, k) = lane_q_.z; \
        LANE((q).w, k) = lane_q_.w; \
    } while (0)

/* a uniform 4D vector (a real4 or float4) in every lane */
#define QUAT_UNIFORM(v) QUAT((lreal)((v).x), (lreal)((v).y), (lreal)((v).z), (lreal)((v).w))

/* A kernel whose work-items each run a packet (march, cone, light terms, Jacobian normals):
 * vec_type_hint says that it is vectorized by hand, so Intel's CPU compiler spends no time on
 * vectorizing it again across work-items: the default scene's march program of 16 lanes
 * built in 1.0-1.2 s instead of 1.8-2.1 s on Intel's CPU runtime, and every kernel ran as fast
 * as before there and on PoCL 3.1 (benchmarks/speed/commit_ratio.py).  One ray per work-item keeps
 * the plain kernel: there the runtime's vectorizing across work-items is what makes it fast. */
#if LANES > 1
#define PACKET_KERNEL __kernel __attribute__((vec_type_hint(LREAL_TYPE)))
#else
#define PACKET_KERNEL __kernel
#endif

/* -D PACKET_PAIRS: a work-item of the march and of the light terms takes two packets, their
 * estimates side by side, where one packet's chain of dependent operations would leave the
 * vector units idle (march/march.cl, shade/light.cl; pipeline/kernel_config.py march_packets).
 * With -D MARCH_UNPAIRED as well, the light terms alone do (LIGHT_PACKETS): the proven march
 * takes one packet, but its shadow rays and occlusion step by the estimate as the estimate
 * march's do. */
#if defined(PACKET_PAIRS) && LANES > 1
#define LIGHT_PACKETS 2
#ifdef MARCH_UNPAIRED
#define PACKETS 1
#else
#define PACKETS 2
#endif
#else
#define PACKETS 1
#define LIGHT_PACKETS 1
#endif

/* A derivative carried only up to scale (the normals' Jacobians: normals/jacobian.cl,
 * kind/julia_stack.cl, kind/cubic_locus.cl) is rescaled on the live lanes where the squared
 * length s2 of its largest part leaves [1e-24, 1e24] (lengths 1e-12 to 1e12), by 1 / sqrt(s2):
 * no overflow or underflow at any max_iter, and no square root until one is due. */
#define L_RESCALE_DUE(live, s2) \
    ((live) & (((s2) > (real)1e24) | (((s2) < (real)1e-24) & ((s2) > (real)0))))

#if LANES > 1
/* The pixels of packet p of work-item g, which takes `packets` neighbouring BLOCK_W x BLOCK_H
 * blocks of a tile tile_w wide and n_items / tile_w high (rows of blocks, each row's blocks
 * grouped `packets` to a work-item): lane_index[k] is lane k's pixel, n_items for a lane
 * past the tile's edge (all of them in a packet past its right edge); returns 0 where the
 * work-item lies below the tile (a padded launch).  Packet 0's lane 0 is always in the tile. */
inline int packet_lanes(size_t g, int p, int packets, int n_items, int tile_w, size_t *lane_index)
{
    int tile_h = n_items / tile_w;
    int blocks_x = (tile_w + BLOCK_W - 1) / BLOCK_W;
    int groups_x = (blocks_x + packets - 1) / packets;
    int bx = ((int)(g % (size_t)groups_x) * packets + p) * BLOCK_W;
    int by = (int)(g / (size_t)groups_x) * BLOCK_H;
    if (by >= tile_h)
        return 0;
    for (int k = 0; k < LANES; ++k) {
        int x = bx + k % BLOCK_W, y = by + k / BLOCK_W;
        lane_index[k] = x < tile_w && y < tile_h ? (size_t)y * tile_w + x : (size_t)n_items;
    }
    return 1;
}

/* one packet per work-item: the g-th block */
inline int block_lanes(size_t g, int n_items, int tile_w, size_t *lane_index)
{
    return packet_lanes(g, 0, 1, n_items, tile_w, lane_index);
}
#endif
