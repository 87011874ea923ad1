/* kind/rotate.cl (-D ROTATE_COS, ROTATE_SIN; built only for fractal.theta != 0): the
 * rotated Julia set of Hart, Sandin & Kauffman 1989 §2.3.  The seed's eqs. 5-6 are lost
 * in its text; reconstructed: the rotation of the complex plane g(z) = u z, u = e^(i theta),
 * conjugates the map,
 *     f_theta(q) = g(f(g^-1(q))) = u f(u^-1 q) + u c,
 * which on the complex plane is e^(-i theta) z^2 + e^(i theta) c for the square, whose Julia
 * set is the unrotated one turned by theta (theta = 90 degrees turns the positive real axis
 * into the positive imaginary one).  In the quaternions u (u^-1 q)^2 = q u^-1 q: the 4D set
 * is the unrotated one left-multiplied by u, an isometric copy, so its 3D sections are other
 * sections of the unrotated set - "completely different shapes".  Left multiplication by
 * u = cos + i sin turns the (1, i) and the (j, k) coordinate pairs both by theta.  The map's
 * norm |f_theta(q) - u c| = |q|^D is unchanged, so the bounding ball, JULIA_DF2 and the
 * distance estimate hold as they are; the derivative is u f'(u^-1 q)[u^-1 h].
 * Compiled between algebra/quaternion.cl and iterate.cl: every later piece iterates the
 * rotated map (julia_f and julia_f_jvp name it from here on). */

/* u q, u = cos t + i sin t (and u^-1 q with s = -sin t), on a lane type (common/lanes.cl) */
inline quat rot_left(quat q, real co, real si)
{
    return QUAT(co * q.x - si * q.y, co * q.y + si * q.x, co * q.z - si * q.w, co * q.w + si * q.z);
}

inline quat rot_f(quat q, real4 c)
{
    return rot_left(julia_f(rot_left(q, (real)(ROTATE_COS), -(real)(ROTATE_SIN)), c),
                    (real)(ROTATE_COS), (real)(ROTATE_SIN));
}

inline quat rot_f_jvp(quat q, quat h)
{
    return rot_left(julia_f_jvp(rot_left(q, (real)(ROTATE_COS), -(real)(ROTATE_SIN)),
                                rot_left(h, (real)(ROTATE_COS), -(real)(ROTATE_SIN))),
                    (real)(ROTATE_COS), (real)(ROTATE_SIN));
}

#define julia_f rot_f
#define julia_f_jvp rot_f_jvp
