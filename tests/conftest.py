import os
import sys
from pathlib import Path

# One BLAS thread in the test process, as in the runners' worker processes (studies.runners): the
# exact formulation's small matrix exponentials get slower, not faster, with threads on a shared
# machine. Set before NumPy is imported.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

sys.path.insert(0, str(Path(__file__).resolve().parent))
