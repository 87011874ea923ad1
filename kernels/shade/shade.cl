/* shade/shade.cl: Lambert diffuse with the light at the eye by default, so every visible
 * point is lit (Hart, Sandin & Kauffman 1989 §4), or at a positioned light (-D LIGHT_POINT); Blinn-Phong
 * specular (-D SPECULAR; Odegaard & Wennergren §5.2); ambient from the sky; background colour on a miss.
 *     rgb = base ambient ao sky
 *         + sum over lights k of  color_k (base diffuse vis_k max(n.l_k, 0) + vis_k specular max(n.h_k, 0)^shininess)
 * the first light being shading.light (color light_color), the others shading.lights
 * (-D EXTRA_LIGHTS=k: lights_geo[j] a 4D position, or with lights_rgb[j].w = 1 the direction
 * towards a distant light; lights_rgb[j].xyz its colour times intensity; their visibility
 * vis_extra[i] with -D EXTRA_SHADOWS),
 * with vis (the light's visibility: shadows) and ao (ambient occlusion) from
 * shade/light.cl's terms (-D LIGHT_TERMS; else 1), and base the scene's colour or, with
 * -D COLORMAP, the colour map's entry for the hit's colour value (terms.z, linear
 * interpolation in a table of n_lut colours); -D FOG fades it toward the background with
 * distance; -D REFLECTION mixes in the mirror bounce (shade/reflect.cl) before it.  All
 * vectors in camera coordinates; linear light; output is float RGBA whatever the precision,
 * in four planes of n_items floats (red, green, blue, alpha): the host's images keep their
 * channels in planes (pipeline/store.py), and files a tile's plane by plane in whole rows. */

/* pixel i's colour v into the four planes */
inline void put_rgba(__global float *rgba, size_t i, int n_items, float4 v)
{
    rgba[i] = v.x;
    rgba[i + (size_t)n_items] = v.y;
    rgba[i + 2 * (size_t)n_items] = v.z;
    rgba[i + 3 * (size_t)n_items] = v.w;
}

__kernel void shade(const int n_items, __global const int *status, __global const real4 *normal,
                    __global const real4 *point, const real4 eye, const real4 right,
                    const real4 up, const real4 forward, const real4 light_pos,
                    const float4 color, const float4 background, const float4 light_color,
                    const float4 sky, const float ambient, const float diffuse, const float specular,
                    const float shininess, __global const float4 *terms, __global const float4 *lut,
                    const int n_lut, const float fog, const float fog_start,
                    __global const real4 *lights_geo, __global const float4 *lights_rgb,
                    __global const float4 *vis_extra, __global const float4 *refl,
                    const float reflection, __global float *rgba)
{
    size_t i = get_global_id(0);
    HITS_ONLY(i, n_items, status, put_rgba(rgba, i, n_items, (float4)(background.xyz, 0.0f)));
    real4 pv = point[i] - eye;
    float3 p = (float3)(DOT4(pv, right), DOT4(pv, up), -DOT4(pv, forward));
    /* the hit is the eye itself (camera inside the set, depth 0): no eye-to-point
     * direction, take the view axis (counted on the host as guards["eye_hit"]) */
    p = UNIT3(p, (float3)(0.0f, 0.0f, -1.0f));
    float3 n = (float3)(normal[i].x, normal[i].y, normal[i].z);
    float3 v = -p;                                   /* towards the eye */
#ifdef LIGHT_POINT
    real4 lv = light_pos - point[i];
    float3 l = UNIT3((float3)(DOT4(lv, right), DOT4(lv, up), -DOT4(lv, forward)), v);
#else
    float3 l = v;
#endif
    float lambert = fmax(DOT3(n, l), 0.0f);
#ifdef LIGHT_TERMS
    float4 tm = terms[i];
    float vis = tm.x, ao = tm.y;
#else
    float vis = 1.0f, ao = 1.0f;
#endif
#ifdef COLORMAP
    float x = clamp(tm.z, 0.0f, 1.0f) * (float)(n_lut - 1);
    int k = min((int)x, n_lut - 2);
    float3 base = mix(lut[k].xyz, lut[k + 1].xyz, x - (float)k);
#else
    float3 base = color.xyz;
#endif
    float3 lit = base * (diffuse * vis * lambert);
#ifdef SPECULAR
    if (lambert > 0.0f) {
        float3 hv = UNIT3(l + v, (float3)(0.0f));   /* none: the light straight behind, no highlight */
        lit += vis * specular * pow(fmax(DOT3(n, hv), 0.0f), shininess);
    }
#endif
    float3 rgb = base * (ambient * ao) * sky.xyz + lit * light_color.xyz;
#ifdef EXTRA_LIGHTS
#ifdef EXTRA_SHADOWS
    float4 ve = vis_extra[i];
#else
    float4 ve = (float4)(1.0f);
#endif
    for (int j = 0; j < EXTRA_LIGHTS; ++j) {
        float4 lc = lights_rgb[j];
        real4 g = lc.w != 0.0f ? lights_geo[j] : lights_geo[j] - point[i];
        float3 lj = UNIT3((float3)(DOT4(g, right), DOT4(g, up), -DOT4(g, forward)), v);
        float vj = j == 0 ? ve.x : (j == 1 ? ve.y : ve.z);
        float lam = fmax(DOT3(n, lj), 0.0f);
        float3 add = base * (diffuse * vj * lam);
#ifdef SPECULAR
        if (lam > 0.0f)
            add += vj * specular * pow(fmax(DOT3(n, UNIT3(lj + v, (float3)(0.0f))), 0.0f), shininess);
#endif
        rgb += add * lc.xyz;
    }
#endif
#ifdef REFLECTION
    rgb = mix(rgb, refl[i].xyz, reflection);   /* shade/reflect.cl's one bounce */
#endif
#ifdef FOG
    /* depth cueing (Hart, Sandin & Kauffman 1989 §4.2): toward the background by exp(-fog (t - fog_start)), t the
     * distance from the eye, fog_start where the bounding ball begins */
    float fade = exp(-fog * fmax((float)sqrt(DOT4(pv, pv)) - fog_start, 0.0f));
    rgb = mix(background.xyz, rgb, fade);
#endif
    put_rgba(rgba, i, n_items, (float4)(rgb, 1.0f));
}
