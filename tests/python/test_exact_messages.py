"""Values in messages as given (issue 45, defect 13): a half-width just above the limit is not rounded into one that
reads as inside the range (a grid file's values: tests/grid_file_test.cpp)."""
import numpy as np
import pytest

import libvox


def cube():
    v = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=np.float64)
    f = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                  [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]], dtype=np.int64)
    return v, f


@pytest.mark.parametrize("half,shown", [(64.0000001, "64.0000001"), (float(np.nextafter(64, 65)), "64.00000000000001"),
                                        (-1e-320, "-1e-320"), (-0.0, "-0")])
def test_sdf_half_width_out_of_range_is_shown_as_given(half, shown):
    message = rf"^sdf: half-width {shown} must be a number in \(0, 64\] cell widths$"
    with pytest.raises(libvox.UsageError, match=message):
        libvox.voxelize(cube(), resolution=4, sdf=half)

