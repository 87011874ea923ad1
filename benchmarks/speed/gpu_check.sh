#!/usr/bin/env bash
# The GPU checks in one run, for a machine with an NVIDIA GPU and no package registry:
# the kernel-against-twin tests on the GPU's OpenCL, the default scene's render time at
# 640x480 and 3840x2160 (warm, median), and the march's throughput against the GPU's FMA
# peak.  Results go to $OUT (default benchmarks/results/gpu), each tagged with commit,
# device and date by the benchmarks themselves.
#
#   bash benchmarks/speed/gpu_check.sh --fetch     # here, with PyPI: the wheels the GPU machine
#                                            # lacks, for its Python, into .whl/
#   bash benchmarks/speed/gpu_check.sh             # there: install .whl/, find NVIDIA's OpenCL, run
#
# Nothing of this is a dependency: without a GPU it says so and stops (status 3).
# PY names the Python there (default python3); WHEEL_PY its version for --fetch (3.12);
# DEVICE=cpu runs the same checks on the CPU, a dry run of this script; DEVICE=oclgrind on
# the OpenCL simulator, with tiny sizes (tests/devices/test_gpu_check.py runs it so, so that
# it cannot rot).  SIZES (default "640x480 3840x2160"), PATH_SIZE (640x480: the path
# tracer's paths per second, at PATH_SAMPLES paths per pixel), THROUGHPUT_SIZE (640x480),
# WIDTHS (the throughput's packet widths, default 1: a GPU runs one ray per work-item),
# REPEATS (10), THROUGHPUT_SCENES (3), PEAK_ITEMS (the FMA peak kernel's work-items, 65536)
# and TESTS (the kernel test files) shrink it.
set -uo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-python3}
OUT=${OUT:-benchmarks/results/gpu}
DEVICE=${DEVICE:-gpu}
# what a render and the kernel tests import beyond what an image with numpy, Pillow,
# pytest, pytest-xdist, matplotlib, scikit-image, tifffile and tqdm already holds
WHEELS="pyopencl==2026.1.4 pytools platformdirs siphash24 OpenEXR OpenImageIO pypng"

if [ "${1:-}" = "--fetch" ]; then
    rm -rf .whl && mkdir -p .whl
    python3 -m pip download -q --no-deps --only-binary=:all: --python-version "${WHEEL_PY:-3.12}" \
        --implementation cp --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 \
        --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 -d .whl $WHEELS || exit 2
    ls -l .whl
    exit 0
fi

mkdir -p "$OUT"
# what is missing, into the Python there (a machine lent for this run alone): tests' child processes set
# PYTHONPATH to the tree they test, which a --target folder on PYTHONPATH would not survive
if ! "$PY" -c "import pyopencl, OpenEXR, OpenImageIO, png" 2>/dev/null && ls .whl/*.whl >/dev/null 2>&1; then
    "$PY" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir .whl/*.whl \
        || { echo "gpu_check: the wheels in .whl did not install"; exit 2; }
fi
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}"
# NVIDIA's OpenCL is its driver's libnvidia-opencl.so.1; a container's driver mount often
# brings the library without an .icd file naming it, so the ICD loader would not see it
if ! grep -qs nvidia /etc/OpenCL/vendors/*.icd; then
    lib=$( (ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}';
            ls /usr/local/nvidia/lib64/libnvidia-opencl.so.1 /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 \
               /usr/lib64/libnvidia-opencl.so.1 2>/dev/null) | head -1)
    if [ -n "$lib" ]; then
        mkdir -p /tmp/gpu_icd && echo "$lib" > /tmp/gpu_icd/nvidia.icd
        export OCL_ICD_VENDORS=/tmp/gpu_icd
    fi
fi
export PYJULIA4D_CACHE=/tmp/gpu_cache PYTHONUNBUFFERED=1
"$PY" -m pyjulia4d devices 2>&1 | tee "$OUT/devices.txt"
# a GPU that is not a simulator (Oclgrind presents itself as one): pyjulia4d's own choice
if [ "$DEVICE" = gpu ] && ! "$PY" -c "from pyjulia4d.opencl.devices import select_device; select_device('gpu')" 2>/dev/null; then
    echo "gpu_check: no OpenCL GPU found (nvidia-smi: $(nvidia-smi -L 2>&1 | head -1)); nothing run"
    exit 3
fi
export PYJULIA4D_DEVICE=$DEVICE
SIZES=${SIZES:-640x480 3840x2160}
REPEATS=${REPEATS:-10}
TESTS=${TESTS:-tests/kernels/test_rays.py tests/kernels/test_iterate.py tests/kernels/test_march.py \
    tests/kernels/test_cone.py tests/kernels/test_normals.py tests/kernels/test_shade.py tests/kernels/test_path.py \
    tests/kernels/test_variants.py tests/kernels/test_algebras.py tests/kernels/test_kinds.py \
    tests/render/test_render.py tests/render/test_bit_identity.py}
status=0
# each kernel stage against its float64 twin, the variants, whole renders and the bit-for-bit
# checks, on the GPU (each test file picks the device from PYJULIA4D_DEVICE)
timeout 300 "$PY" -m pytest -q -n "${JOBS:-8}" -p no:cacheprovider $TESTS 2>&1 \
    | tee "$OUT/tests.txt" | tail -25
[ "${PIPESTATUS[0]}" = 0 ] || status=1
for size in $SIZES; do
    timeout 120 "$PY" benchmarks/speed/render_time.py --device "$DEVICE" --repeats "$REPEATS" --out "$OUT" \
        --set "image.width=${size%x*}" --set "image.height=${size#*x}" || status=1
done
# the path tracer: its paths per second on the default scene
size=${PATH_SIZE:-640x480}
timeout 300 "$PY" benchmarks/speed/render_time.py --device "$DEVICE" --repeats "$REPEATS" --out "$OUT" \
    --set "image.width=${size%x*}" --set "image.height=${size#*x}" --set shading.integrator=path \
    --set "image.samples=${PATH_SAMPLES:-16}" || status=1
timeout 200 "$PY" benchmarks/speed/throughput.py --device "$DEVICE" --repeats 3 --size "${THROUGHPUT_SIZE:-640x480}" \
    --widths "${WIDTHS:-1}" --scenes "${THROUGHPUT_SCENES:-3}" --peak-items "${PEAK_ITEMS:-65536}" --out "$OUT" 2>&1 | tail -30
[ "${PIPESTATUS[0]}" = 0 ] || status=1
exit $status
