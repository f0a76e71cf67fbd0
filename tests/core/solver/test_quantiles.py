"""The solver's quantiles come from scipy.special (light to import); they are the distributions' own, checked against
scipy.stats's quantile functions and against the tail probability they leave."""

import numpy as np
import pytest
from scipy import stats

from calib_core.solver.misfit import FALSE_FLAG_PER_SOLVE, fisher_quantile


@pytest.mark.parametrize("n_tested, dof", [(4, 2), (6, 5), (20, 34), (200, 394)])
def test_the_fisher_quantile_is_f_s_and_leaves_one_false_flag_per_thousand_solves(n_tested, dof):
    q = fisher_quantile(n_tested, dof)
    assert q == pytest.approx(stats.f.ppf(1.0 - FALSE_FLAG_PER_SOLVE / n_tested, 2, dof), rel=1e-10)
    assert stats.f.sf(q, 2, dof) * n_tested == pytest.approx(FALSE_FLAG_PER_SOLVE, rel=1e-8)


def test_the_chi_square_upper_quantile_is_chi_square_s():
    from scipy.special import chdtri

    for dof in (1, 6, 30):
        assert chdtri(dof, 0.001) == pytest.approx(stats.chi2.ppf(0.999, dof), rel=1e-10)
    assert np.isclose(stats.chi2.sf(chdtri(6, 0.01), 6), 0.01)
