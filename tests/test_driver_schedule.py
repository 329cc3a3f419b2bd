"""Chunk claiming of the batch kernels: every state in exactly one chunk, in order."""

import numpy as np
import pytest
import numba
from numba import njit

from robodyn.algorithms.driver import MIN_CHUNK, chunks, claim


@njit
def _claimed(B, nchunk):
    counter = np.zeros(1, np.int64)
    out = np.zeros((nchunk + 3, 2), np.int64)
    for c in range(nchunk + 3):  # more claims than chunks: the extra ones are empty
        out[c, 0], out[c, 1] = claim(counter, B, nchunk)
    return out, counter[0]


@pytest.mark.parametrize("B", [1, 2, 7, 64, 1000, 100_003])
def test_claims_cover_every_state_once(B):
    nchunk = chunks(B)
    assert 1 <= nchunk <= B
    assert nchunk <= max(numba.get_num_threads(), -(-B // MIN_CHUNK))  # chunks of a small batch stay large
    bounds, count = _claimed(B, nchunk)
    assert count == nchunk + 3
    lo, hi = bounds[:nchunk, 0], bounds[:nchunk, 1]
    assert lo[0] == 0 and hi[-1] == B and np.all(lo[1:] == hi[:-1]) and np.all(hi > lo)
    assert np.all(bounds[nchunk:, 0] >= bounds[nchunk:, 1])  # nothing left
