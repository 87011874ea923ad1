"""``python -m pyjulia4d`` and the ``pyjulia4d`` command."""
import errno
import os
import sys


_OUTPUT_ERRNOS = (errno.EPIPE, errno.ENOSPC, errno.EIO, errno.EFBIG, errno.EDQUOT)


def run() -> int:
    """The program: what only a process of its own may set, then the command line (app/cli.py).

    OpenBLAS starts a thread per core when numpy is imported, which cost 0.1 of the 0.5 CPU-s
    of a tiny render here; the renderer uses no BLAS worth threads (the kernels run in OpenCL),
    so one thread, unless the user set it.  The default device's runtime may be loaded alone
    (opencl/default_device.py).  What the command prints escapes what the terminal's encoding
    cannot show (PYTHONIOENCODING=ascii and a file named "é.png": the render was written,
    then its closing line failed as an error)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    for stream in (sys.stdout, sys.stderr):
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")
    from pyjulia4d.app.cli import main
    from pyjulia4d.opencl import default_device

    default_device.allow()
    try:
        status = main()
        sys.stdout.flush()
        return status
    except OSError as e:
        # what a failing standard output raises (a file's own error names the file); any
        # other OSError the command did not expect keeps its traceback
        if e.filename is not None or e.errno not in _OUTPUT_ERRNOS:
            raise
        # standard output failed: its reader went away (`| head`), or it is full (/dev/full);
        # what is still buffered goes nowhere, so that the exit's own flush cannot fail again
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
        os.close(null)
        if isinstance(e, BrokenPipeError):
            return 128 + 13   # as the shell's own tools end on SIGPIPE
        print(f"pyjulia4d: error: cannot write to standard output: {e.strerror or e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    raise SystemExit(run())
