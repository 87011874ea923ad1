/* shade/reflect.cl (-D REFLECTION): one mirror bounce of each hit, in the set itself and
 * in the background (Hart, Sandin & Kauffman 1989 §6: reflection is among what ray tracing gives over earlier
 * methods).  reflect_rays makes the reflected ray of each hit,
 *     d' = d - 2 (d . n) n,  from p + bias n  (n the 4D unit normal, d the unit view ray),
 * which march.cl (-D RAYS_FROM_BUFFERS) marches like a camera ray; reflect_color lights
 * what it hits with the key light alone, no shadows (one bounce: the reflection of a
 * reflection is not traced):
 *     rgb' = color (ambient sky + diffuse max(n' . l, 0) light_color),  background on a miss,
 * l towards shading.light, or back along the reflected ray for the light at the eye;
 * shade.cl mixes it in: rgb = mix(rgb, rgb', reflection) (before depth cueing). */

__kernel void reflect_rays(const int n_items, __global const real4 *point, __global const real4 *normal,
                           __global const int *status, const real4 eye, const real4 right, const real4 up,
                           const real4 forward, const real bias, const real radius,
                           __global real4 *origins, __global real4 *dirs)
{
    size_t i = get_global_id(0);
    /* a miss: outside the bounding ball, leaving it (march.cl finds an empty interval) */
    HITS_ONLY(i, n_items, status, (origins[i] = (real4)(4 * radius, 0, 0, 0), dirs[i] = (real4)(1, 0, 0, 0)));
    real4 p = point[i];
    real4 nc = normal[i];
    real4 n = nc.x * right + nc.y * up - nc.z * forward;
    real4 d = p - eye;
    real dd = DOT4(d, d);   /* not dot(): common/lanes.cl DOT3 */
    d = dd > 0 ? d / sqrt(dd) : forward;        /* the eye inside the set: the view axis */
    real4 r = d - 2 * DOT4(d, n) * n;
    real rr = DOT4(r, r);
    dirs[i] = rr > 0 ? r / sqrt(rr) : -d;
    origins[i] = p + bias * n;
}

__kernel void reflect_color(const int n_items, __global const int *status, __global const real4 *normal,
                            __global const real4 *point, __global const real4 *dirs, const real4 right,
                            const real4 up, const real4 forward, const real4 light_pos,
                            const float4 color, const float4 background, const float4 light_color,
                            const float4 sky, const float ambient, const float diffuse,
                            __global float4 *refl)
{
    size_t i = get_global_id(0);
    HITS_ONLY(i, n_items, status, refl[i] = (float4)(background.xyz, 0.0f));
    real4 nc = normal[i];
    real4 n = nc.x * right + nc.y * up - nc.z * forward;
#ifdef LIGHT_POINT
    real4 l = light_pos - point[i];
    real ll = DOT4(l, l);
    l = ll > 0 ? l / sqrt(ll) : -dirs[i];
#else
    real4 l = -dirs[i];
#endif
    float lambert = fmax((float)DOT4(n, l), 0.0f);
    float3 rgb = color.xyz * (ambient * sky.xyz + diffuse * lambert * light_color.xyz);
    refl[i] = (float4)(rgb, 1.0f);
}
