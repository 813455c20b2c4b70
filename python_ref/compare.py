"""Compare a `tubemem run` folder with the independent references (the checkout's entry point;
the code is `tubemem_ref.compare`, also `python -m tubemem_ref.compare`).

    python python_ref/compare.py RUN_DIR [--out RUN_DIR/compare] [--no-plot]
"""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from tubemem_ref.compare import compare, main  # noqa: E402,F401

if __name__ == "__main__":
    main()
