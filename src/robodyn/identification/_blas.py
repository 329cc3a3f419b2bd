"""Small dense linear algebra on one BLAS thread.

The identification solves many small problems (tens of columns) in loops: the excitation
optimisation and the physically consistent fit. Multi-threaded BLAS gains nothing on such
sizes, and when its threads compete with the compiled kernels' threads or other processes
for the cores, each call can wait for milliseconds to seconds (measured: a 420 x 57 SVD
from 1 ms to 0.5 s on a loaded 2-core machine). ``one_blas_thread()`` limits BLAS to one
thread for the duration of a ``with`` block (threadpoolctl).
"""

from __future__ import annotations


def one_blas_thread():
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")
