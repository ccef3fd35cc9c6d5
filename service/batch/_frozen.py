"""Imported last by the local workers' forkserver, for one effect: ``gc.freeze()``.

Everything the forkserver imported before (Dask, numpy, the pipeline) moves to
the garbage collector's permanent generation, as Python's documentation
advises before forking: the workers' collections then never walk (and so
never copy-on-write) those inherited objects, and the forkserver's and the
workers' exits skip the final collections over them.
"""

import gc

gc.freeze()
