"""float64 twin of kernels/function/pwr.cl: f(z) = z^p = exp(p log z), p = x + iy the
scene's fractal.exponent (POV-Ray 3.6 documentation, "pwr(x, y)"); 0^p = 0, as the kernel."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z, p):
    with np.errstate(all="ignore"):
        r = np.exp(p * np.log(z))
    return np.where(z == 0, 0, r)


def cfun_d(z, p):
    """p z^(p-1) as p z^p / z (the kernel shares z^p's log and exp with cfun); 0 at 0."""
    with np.errstate(all="ignore"):
        r = p * cfun(z, p) / z
    return np.where(z == 0, 0, r)


def cfun_disc(z, p):
    """The disc enclosure of z^p = exp(p log z), both sides of log's cut (kernels/function/pwr.cl)."""
    return D.d_pwr(z, p)


def FUNC_M2(m, rho, p):
    """|p (p - 1) z^(p - 2)| <= |p (p - 1)| e^(max(Re q ln|z|) + |Im q| pi), q = p - 2, over the
    disc; none (inf) where it meets log's cut or 0 (kernels/function/pwr.cl)."""
    qr, qi = p.real - 2, p.imag
    with np.errstate(all="ignore"):
        # max(qr ln s) over s in [|m| - rho, |m| + rho]: one end by qr's sign
        e = (qr * np.log(np.abs(m) + rho) if qr > 0 else qr * np.log(np.abs(m) - rho) if qr < 0
             else np.zeros(np.shape(m))) + abs(qi) * D.ENC_PI
        if qi == 0 and float(p.real).is_integer():   # analytic across the cut (PWR_INTEGER)
            e = np.where(qr == 0, 0.0, e)
            bad = (qr < 0) & ~(np.abs(m) > rho)
        else:
            bad = D.d_meets_cut((m, rho)) | ~(np.abs(m) > rho)
        return np.where(bad, np.inf, abs(p) * abs(p - 1) * np.exp(e) * D.rounding().up)


def FUNC_ROUND_GAIN(m, p):
    """exp(p log z) loses |p log z| ulps of its value (kernels/function/pwr.cl)."""
    with np.errstate(all="ignore"):
        return 1 + abs(p) * (np.abs(np.log(np.abs(m))) + D.ENC_PI)
