"""The automatic choice of the number of UDCT scales (``wedges="auto"``, :func:`csmri.choose_scales`).

The hold-out rule was developed on the camera, astronaut, moon, coins and brick photographs,
a Shepp-Logan raster and the 12-pixel lattice (256 x 256, Cartesian mask seed 3), and on the
12- and 14-pixel lattices, the camera and the brick under pseudo-radial masks (25 to 35 %
of the samples). The images here are others: scikit-image's cat, text and retina
photographs, its own Shepp-Logan phantom, and a lattice of another period, with other masks.
"""

import numpy as np
import pytest
from skimage import color, data, transform

from results_check import check_result
from wscg import csmri

N = 256
SIX = [6, 6]


def _image(name):
    if name == "lattice10":
        return csmri.make_diamond_lattice(N, period=10.0).astype(complex)
    if name == "shepp_logan":
        a = data.shepp_logan_phantom()
    else:
        a = getattr(data, name)()
    if a.ndim == 3:
        a = color.rgb2gray(a[..., :3])
    a = transform.resize(a.astype(float), (N, N), anti_aliasing=True)
    return (a / a.max()).astype(complex)


def _case(name):
    img = _image(name)
    if name.startswith("lattice"):
        m, _ = csmri.mask_pseudo_radial((N, N), 0.302)
    else:
        m = csmri.mask_cartesian((N, N), 0.4, seed=8)
    return csmri.simulate(img, m), m, img


@pytest.mark.parametrize("name", ["chelsea", "text", "retina", "shepp_logan", "lattice10"])
def test_automatic_scales_are_within_0_3_db_of_the_best_number_of_scales(name):
    k, m, img = _case(name)
    per_j = {j: csmri.psnr(img, csmri.reconstruct(k, m, wedges=[SIX] * j)) for j in (1, 2, 3)}
    choice = csmri.choose_scales(k, m)
    auto = csmri.reconstruct(k, m)
    # The default is the chosen number of scales, bit for bit.
    assert np.array_equal(auto, csmri.reconstruct(k, m, wedges=[SIX] * choice.scales))
    got, best = csmri.psnr(img, auto), max(per_j.values())
    print(f"{name}: J=1/2/3 " + " / ".join(f"{per_j[j]:.2f}" for j in (1, 2, 3))
          + f" dB, auto J={choice.scales} {got:.2f} dB")
    assert got >= best - 0.3, (name, per_j, choice.scales)


def test_choice_result_and_its_scores():
    k = csmri.make_shepp_logan_kspace(64)
    m = csmri.mask_cartesian((64, 64), 0.4, seed=2)
    c = csmri.choose_scales(k, m, max_iter=15, candidates=(2, 1), folds=2, seed=4)
    check_result(c, csmri.ScaleChoice)
    assert c.candidates == (2, 1) and c.scores.shape == (2, 2)
    assert c.held_out == round(0.05 * m.sum())
    assert np.all(np.isfinite(c.scores)) and np.all(c.scores > 0)
    assert c.scales == c.candidates[int(np.argmin(c.scores.sum(axis=1)))]
    # Another seed draws other hold-out sets: other scores.
    d = csmri.choose_scales(k, m, max_iter=15, candidates=(2, 1), folds=2, seed=5)
    assert not np.array_equal(c.scores, d.scores)
    # The cluster radius reaches the draw: single samples (0) hold out as many samples in
    # other places, so other scores; the radius is the last keyword.
    e = csmri.choose_scales(k, m, max_iter=15, candidates=(2, 1), folds=2, seed=4, cluster=0)
    assert e.held_out == c.held_out and not np.array_equal(c.scores, e.scores)
    # Fully sampled data has nothing unmeasured: the first candidate, unscored.
    full = csmri.choose_scales(k, np.ones((64, 64), bool), candidates=(3, 1))
    assert (full.scales, full.held_out, full.scores.size) == (3, 0, 0)


def test_bad_settings_name_the_argument():
    k = csmri.make_shepp_logan_kspace(32)
    m = csmri.mask_cartesian((32, 32), 0.4, seed=2)
    for kwargs, name in [({"candidates": ()}, "candidates"), ({"candidates": (0,)}, "candidates"),
                         ({"folds": 0}, "folds"), ({"holdout": 0.0}, "holdout"),
                         ({"folds": 4, "holdout": 0.3}, "holdout"), ({"candidates": (8,)}, "candidates"),
                         ({"cluster": -1.0}, "cluster"), ({"cluster": 17}, "cluster")]:
        with pytest.raises(ValueError, match=name):
            csmri.choose_scales(k, m, **kwargs)
    with pytest.raises(ValueError, match="wedges"):
        csmri.reconstruct(k, m, wedges="best")
