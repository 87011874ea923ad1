/* march/clip.cl (-D CLIP): the normal of a hit on a cut face (march.cl's FLAG_CUT_FACE) is
 * its plane's, pointing out of the kept half-space (clip_n[k], the world normal of
 * n . p <= offset), in camera coordinates like every normal (x right, y up, z towards the
 * eye). */
__kernel void clip_normals(const int n_items, __global const int *flags, __global const int *status,
                           const real4 right, const real4 up, const real4 forward, const real4 clip_n0,
                           const real4 clip_n1, const real4 clip_n2, const real4 clip_n3,
                           __global real4 *normal)
{
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    int f = flags[i];
    if (status[i] != STATUS_HIT || !(f & FLAG_CUT_FACE))
        return;
    int k = (f >> 5) & 3;
    real4 n = CLIP_NORMAL(k);
    real3 c = (real3)(DOT4(n, right), DOT4(n, up), -DOT4(n, forward));   /* common/lanes.cl DOT3 */
    c *= rsqrt(DOT3(c, c));   /* n is a unit 4-vector (plan.py), its 3D image not 0 */
    normal[i] = (real4)(c.x, c.y, c.z, 0);
}
