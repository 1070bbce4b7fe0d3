#!/bin/bash
# symprk gpucheck and the suite's Common-kernel tests on a GPU machine that has Python and NVIDIA's CUDA 13 Python
# packages (nvidia-cuda-runtime, -nvrtc, -cufft: cu13) but no openmm, and no network.  How docs/data/gpucheck was
# made (an H100 and an H200, CPython 3.12).  Prepare, on a machine with network, in the repository root:
#
#   python3.12 -m pip wheel --no-deps -w wheels .           # this package, built for the GPU machine's Python
#   python3.12 -m pip download --no-deps -d wheels openmm==8.6.1 openmm-cuda-13==8.6.1 pymbar numexpr
#
# then on the GPU machine, in the repository root:  WHEELS=wheels OUT=gpucheck-out tools/gpu_check.sh
# (GPUCHECK_ARGS: e.g. --quick; PYTEST_FILES: what to test, default the files of tests/integrators that hold the
# Common-kernel tests; GPUCHECK_S, LAUNCHES_S, PYTEST_S: time limits in seconds).
set -o pipefail
REPO=$(pwd)
WHEELS=${WHEELS:-wheels}
OUT=${OUT:-gpucheck-out}
mkdir -p "$OUT" && OUT=$(cd "$OUT" && pwd)
export PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/symprk-site \
    "$WHEELS"/*.whl || exit 3
export PYTHONPATH=/tmp/symprk-site
# openmm-cuda-13 finds cuFFT and NVRTC beside itself (nvidia/cu13/lib); here they are the machine's own packages
NV=$(python3 -c "import nvidia; print(list(nvidia.__path__)[0])")
export LD_LIBRARY_PATH=$NV/cu13/lib:$LD_LIBRARY_PATH
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv | tee "$OUT/env.txt"
cd /tmp && python3 - <<'PY' 2>&1 | tee -a "$OUT/env.txt"
import sys

import numpy
import openmm as mm

print(sys.version.split()[0], "numpy", numpy.__version__, "OpenMM", mm.version.full_version)
print([mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())])
print("load failures:", mm.Platform.getPluginLoadFailures())
from openmm_symprk import plugin

print("plugin", plugin.available(), plugin.details())
PY
cd /tmp && timeout "${GPUCHECK_S:-600}" python3 -m openmm_symprk.cli gpucheck $GPUCHECK_ARGS 2>&1 \
    | tee "$OUT/gpucheck.md"
echo "gpucheck rc=$?" | tee -a "$OUT/gpucheck.md"
# every launch and host copy per step (the CUDA driver API intercept of tools/count_launches.py; needs g++), mixed
# precision, the 2.2 nm box of docs/native.md's table and the speed table's 3.9 nm one
if command -v g++ > /dev/null; then
    for BOX in 2.2 3.9; do
        timeout "${LAUNCHES_S:-900}" python3 "$REPO/tools/count_launches.py" --platform CUDA --box-nm $BOX --kernels \
            --build-dir /tmp/symprk-intercept --json "$OUT/launches-cuda-$BOX.json" 2>&1 | tee "$OUT/launches-cuda-$BOX.md"
    done
fi
# the tests run from a copy beside the installed package, so that `import openmm_symprk` is the wheel's
rm -rf /tmp/tests && cp -r "$REPO/tests" /tmp/tests && cp "$REPO/pyproject.toml" /tmp/pyproject.toml && cd /tmp/tests
FILES=${PYTEST_FILES:-$(cd integrators && grep -l "COMMON" test_*.py | sed 's#^#integrators/#' | tr '\n' ' ')}
SYMPRK_TEST_COMMON_PLATFORM=CUDA timeout "${PYTEST_S:-600}" python3 -m pytest -q -p no:cacheprovider -rfEs \
    --durations=5 $FILES 2>&1 | tee "$OUT/pytest-cuda.txt"
echo "pytest rc=$?" | tee -a "$OUT/pytest-cuda.txt"
