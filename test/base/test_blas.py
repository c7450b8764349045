"""The BLAS limit, read back through threadpoolctl's own report of the loaded libraries."""

import ast
import subprocess
import sys

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from lumpbeam_ros.base.blas import single_threaded_blas


def _blas_threads():
    return [pool['num_threads'] for pool in threadpool_info() if pool['user_api'] == 'blas']


@pytest.fixture
def two_threads():
    """Every BLAS at two threads (whatever the environment set), restored afterwards."""
    assert _blas_threads(), 'no BLAS that threadpoolctl can see (numpy wheels bring OpenBLAS)'
    with threadpool_limits(limits=2, user_api='blas'):
        yield


def test_every_blas_runs_one_thread_inside_and_is_restored_after(two_threads):
    assert set(_blas_threads()) == {2}
    with single_threaded_blas():
        assert set(_blas_threads()) == {1}
    assert set(_blas_threads()) == {2}


def test_the_limit_nests_and_is_restored_after_an_error(two_threads):
    with pytest.raises(RuntimeError, match='inside'):
        with single_threaded_blas():
            with single_threaded_blas():
                assert set(_blas_threads()) == {1}
            assert set(_blas_threads()) == {1}
            raise RuntimeError('inside')
    assert set(_blas_threads()) == {2}


def test_one_thread_computes_the_same_products():
    rng = np.random.default_rng(3)
    a, b = rng.standard_normal((60, 40)), rng.standard_normal((40, 30))
    with single_threaded_blas():
        inside = a @ b
        solved = np.linalg.lstsq(a, a @ np.arange(40.0), rcond=None)[0]
    np.testing.assert_allclose(inside, a @ b, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(solved, np.arange(40.0), rtol=1e-9, atol=1e-9)


def test_a_blas_loaded_after_the_first_limit_is_limited_too():
    # In a fresh interpreter: the first limit sees numpy's BLAS only; scipy's, loaded later,
    # must be limited by the next one.
    code = (
        'from threadpoolctl import threadpool_info, threadpool_limits\n'
        'from lumpbeam_ros.base.blas import single_threaded_blas\n'
        'with single_threaded_blas(): pass\n'
        'import scipy.linalg\n'
        'with threadpool_limits(limits=2, user_api="blas"), single_threaded_blas():\n'
        '    print(sorted((p["filepath"], p["num_threads"]) for p in threadpool_info()'
        ' if p["user_api"] == "blas"))\n'
    )
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    pools = ast.literal_eval(result.stdout)
    # numpy's and scipy's wheels each bring their own OpenBLAS: two pools, the later one too.
    assert len(pools) >= 2, pools
    assert {threads for _, threads in pools} == {1}
