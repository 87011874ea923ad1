/* path/sample.cl: the path tracer's random numbers and the densities it samples, written
 * once for path/path.cl and mirrored operation for operation by reference/path_sample.py.
 *
 * Random numbers are counter-based and low-discrepancy: dimension k of sample s of pixel p
 * (p = y width + x in the whole image) depends on those three alone, so a pixel's paths are
 * the same whatever the tiles, the workers or the order they run in.  Dimensions come in
 * pairs (2j, 2j + 1), and a pair's points over a pixel's samples s = 0, 1, 2, ... are the
 * first two dimensions of Sobol's sequence, Owen-scrambled - the index shuffled and each
 * coordinate scrambled by hash-based nested uniform scrambles seeded by the pixel and the
 * pair (Burley, "Practical Hash-based Owen Scrambling", 2020, §3-4: the Laine-Karras
 * permutation between bit reversals; each pair padded with its own seeds, as pbrt-v4's
 * PaddedSobolSampler).  So every 2^m samples of a pair are stratified in every 2^a x 2^b
 * grid with a + b = m (a (0, 2)-net), and the pairs of one path are independent of each
 * other.  The seeds are Wellons' "lowbias32" integer mix of the pixel and the pair; a
 * coordinate's top 24 bits over 2^24 give a number in [0, 1) that float and double hold
 * exactly.
 *
 * The material (Walter, Marschner, Li & Torrance, "Microfacet Models for Refraction
 * through Rough Surfaces", 2007, §5.2 eqs. 33-34: GGX; Burley, "Physically Based Shading at
 * Disney", 2012, §5.3: metallic and the specular F0 = 0.08 specular):
 *     f(v, l) = (1 - metallic) base / pi + D(h) G(v, l) F(v . h) / (4 (n . v) (n . l))
 *     D(h) = a^2 / (pi ((n . h)^2 (a^2 - 1) + 1)^2),   a = max(roughness^2, ALPHA_MIN)
 *     G = G1(v) G1(l),  G1(x) = 2 (n . x) / ((n . x) + sqrt(a^2 + (1 - a^2) (n . x)^2))
 *     F(u) = mix(min(2 specular S(0.04, u), 1), S(base, u), metallic),  S(f0, u) = f0 + (1 - f0) (1 - u)^5
 * (Schlick): a metal's Fresnel from its colour, a dielectric's the physical one of F0 = 0.04
 * scaled by 2 specular (Burley's 0.08 specular at normal incidence) - all of it, grazing rise
 * too, so that specular = 0 leaves a Lambertian surface, which returns its albedo exactly
 * sampled by one lobe chosen with probability p_spec (spec_share) and weighed by the sum
 * of both lobes' densities (one-sample multiple importance sampling of the two):
 *     pdf(l) = p_spec D(h) (n . h) / (4 (v . h)) + (1 - p_spec) (n . l) / pi.
 * All vectors here are 3D, in camera coordinates (right, up, towards the eye): the rays of a
 * 4D camera stay in its 3D space (Odegaard & Wennergren §4). */

#define PATH_PI 3.14159265358979323846
#define ALPHA_MIN 0.002     /* GGX's width floor: a mirror of float32 directions */

/* A 3-vector held in a real4 with w = 0.  Not pvec: Intel's CPU compiler, vectorising
 * across work-items, mixed the lanes of the two sides' double3 values where work-items took
 * different branches (kernel against twin: a bounce's direction, a light's, a unit vector);
 * its four-wide vectors are the march's own types and vectorise right. */
typedef real4 pvec;
#define PVEC(x, y, z) ((real4)((x), (y), (z), (real)0))

inline uint path_mix(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* x with its 32 bits in reverse order */
inline uint path_reverse(uint x)
{
    uint r = 0u;
    for (int k = 0; k < 32; ++k) {
        r = (r << 1) | (x & 1u);
        x >>= 1;
    }
    return r;
}

/* Burley's nested uniform scramble of x: the Laine-Karras permutation of its reversed bits */
inline uint path_owen(uint x, uint seed)
{
    x = path_reverse(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return path_reverse(x);
}

/* the second dimension of Sobol's sequence at index i: direction numbers v_0 = 2^31,
 * v_(k+1) = v_k ^ (v_k >> 1) (the first dimension is the bit reversal of i) */
inline uint path_sobol1(uint i)
{
    uint r = 0u, v = 0x80000000u;
    for (int k = 0; k < 32; ++k) {
        r ^= v & (0u - ((i >> k) & 1u));
        v ^= v >> 1;
    }
    return r;
}

/* the seed of pair ``pair`` of pixel ``pixel``'s dimensions, and coordinate ``odd`` (0 or 1)
 * of the pair's point at the shuffled index i, in [0, 1) */
inline uint path_seed(uint pixel, uint pair)
{
    return path_mix(pixel ^ path_mix(pair + 0x9e3779b9u));
}

inline real path_coord(uint i, uint seed, uint odd)
{
    uint x = odd ? path_sobol1(i) : path_reverse(i);
    x = path_owen(x, path_mix(seed ^ (odd ? 0x68bc21ebu : 0x02e5be93u)));
    return (real)(x >> 8) * (real)(1.0 / 16777216.0);
}

/* dimension ``dim`` of sample ``s`` of pixel ``pixel``: a number in [0, 1) (see above) */
inline real path_rand(uint pixel, uint s, uint dim)
{
    uint seed = path_seed(pixel, dim >> 1);
    return path_coord(path_owen(s, seed), seed, dim & 1u);
}

/* dimensions ``dim`` and dim + 1 (dim even: one pair) at once, the index shuffled once:
 * path_rand's two numbers */
inline real2 path_rand2(uint pixel, uint s, uint dim)
{
    uint seed = path_seed(pixel, dim >> 1);
    uint i = path_owen(s, seed);
    return (real2)(path_coord(i, seed, 0u), path_coord(i, seed, 1u));
}

/* a / |a|, (0, 0, 1) where a is 0 */
inline pvec path_unit(pvec a)
{
    real aa = DOT3(a, a);
    real k = (real)1 / sqrt(aa > (real)0 ? aa : (real)1);
    return aa > (real)0 ? PVEC(a.x * k, a.y * k, a.z * k) : PVEC(0, 0, 1);
}

/* x t + y b + z n, with t, b the unit vectors that make (t, b, n) right-handed and
 * orthonormal (Duff, Burgess, Christensen, Hery, Kensler, Liani & Villemin, "Building an
 * Orthonormal Basis, Revisited", 2017, Listing 3) */
inline pvec path_local(pvec n, real x, real y, real z)
{
    real sgn = n.z >= (real)0 ? (real)1 : (real)-1;
    real a = (real)-1 / (sgn + n.z);
    real c = n.x * n.y * a;
    real tx = (real)1 + sgn * n.x * n.x * a, ty = sgn * c, tz = -sgn * n.x;
    real bx = c, by = sgn + n.y * n.y * a, bz = -n.y;
    return PVEC(x * tx + y * bx + z * n.x, x * ty + y * by + z * n.y, x * tz + y * bz + z * n.z);
}

/* Shirley & Chiu's concentric map of the unit square onto the unit disc ("A Low Distortion
 * Map Between Disk and Square", 1997), as pbrt-v4's SampleUniformDiskConcentric. */
inline real2 path_disc(real u1, real u2)
{
    real a = (real)2 * u1 - (real)1, b = (real)2 * u2 - (real)1;
    if (a == (real)0 && b == (real)0)
        return (real2)(0, 0);
    real r, phi;
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (real)(PATH_PI / 4) * (b / a);
    } else {
        r = b;
        phi = (real)(PATH_PI / 2) - (real)(PATH_PI / 4) * (a / b);
    }
    return (real2)(r * cos(phi), r * sin(phi));
}

/* a cosine-weighted direction about n: density (n . l) / pi */
inline pvec path_cosine(pvec n, real u1, real u2)
{
    real r = sqrt(u1), phi = (real)(2 * PATH_PI) * u2;
    return path_local(n, r * cos(phi), r * sin(phi), sqrt(fmax((real)1 - u1, (real)0)));
}

inline real ggx_d(real nh, real a2)
{
    real k = nh * nh * (a2 - (real)1) + (real)1;
    return a2 / ((real)PATH_PI * k * k);
}

inline real ggx_g1(real nx, real a2)
{
    return (real)2 * nx / (nx + sqrt(a2 + ((real)1 - a2) * nx * nx));
}

inline real schlick(real f0, real u)
{
    real m = (real)1 - clamp(u, (real)0, (real)1);
    real m2 = m * m;
    return f0 + ((real)1 - f0) * m2 * m2 * m;
}

/* F(u) of the docstring; f0s = 0.08 specular */
inline pvec fresnel(pvec base, real metallic, real f0s, real u)
{
    real fd = fmin(f0s * (real)25 * schlick((real)0.04, u), (real)1);
    return PVEC(fd + (schlick(base.x, u) - fd) * metallic, fd + (schlick(base.y, u) - fd) * metallic,
                fd + (schlick(base.z, u) - fd) * metallic);
}

/* the half vector of the GGX lobe from (u1, u2) (its density D(h) (n . h)) */
inline pvec ggx_half(pvec n, real a2, real u1, real u2)
{
    real ct = sqrt(((real)1 - u1) / ((real)1 + (a2 - (real)1) * u1));
    real st = sqrt(fmax((real)1 - ct * ct, (real)0));
    real phi = (real)(2 * PATH_PI) * u2;
    return path_local(n, st * cos(phi), st * sin(phi), ct);
}

/* luminance of linear Rec. 709 / sRGB primaries */
inline real path_lum(pvec c)
{
    return (real)0.2126 * c.x + (real)0.7152 * c.y + (real)0.0722 * c.z;
}

/* The share of samples the specular lobe takes at a hit seen from v: its Fresnel weight
 * against the diffuse albedo, kept in [0.1, 0.9] where both lobes are there. */
inline real spec_share(pvec base, real metallic, real f0s, real nv)
{
    real ks = path_lum(fresnel(base, metallic, f0s, nv));
    real kd = ((real)1 - metallic) * path_lum(base);
    if (kd <= (real)0)
        return (real)1;
    if (ks <= (real)0)
        return (real)0;
    return clamp(ks / (ks + kd), (real)0.1, (real)0.9);
}

/* f(v, l) (n . l) and the density of l under the lobe mix: .xyz the first, .w the second */
inline real4 bsdf_eval(pvec n, pvec v, pvec l, pvec base, real metallic, real f0s, real a2, real p_spec)
{
    real nl = DOT3(n, l), nv = DOT3(n, v);
    if (nl <= (real)0 || nv <= (real)0)
        return (real4)(0, 0, 0, 0);
    pvec f = ((real)1 - metallic) * base * (real)(1 / PATH_PI);
    real pdf = ((real)1 - p_spec) * nl * (real)(1 / PATH_PI);
    if (p_spec > (real)0) {
        pvec h = path_unit(v + l);
        real nh = fmax(DOT3(n, h), (real)0), vh = fmax(DOT3(v, h), (real)1e-12);
        real d = ggx_d(nh, a2);
        f += fresnel(base, metallic, f0s, vh) * (d * ggx_g1(nv, a2) * ggx_g1(nl, a2) / ((real)4 * nv * nl));
        pdf += p_spec * d * nh / ((real)4 * vh);
    }
    return (real4)(f.xyz * nl, pdf);
}

/* the power heuristic (beta = 2) of a sample of density a against another of density b
 * (Veach, "Robust Monte Carlo Methods for Light Transport Simulation", 1997, §9.2.4) */
inline real power_weight(real a, real b)
{
    real a2 = a * a, b2 = b * b;
    return a2 + b2 > (real)0 ? a2 / (a2 + b2) : (real)0;
}
