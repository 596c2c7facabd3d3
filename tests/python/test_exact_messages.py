"""Values in messages as given (issue 45, defect 13): a half-width just above the limit is not rounded into one that
reads as inside the range (a grid file's values: tests/grid_file_test.cpp), nor a tiny side as 0.000000."""
import subprocess

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



def test_the_binvox_warning_prints_vox_exports_numbers(tools, tmp_path):
    """Cells of 1e-7 by 1e-7 by 2e-7: Grid.save's warning gives the voxels' side as vox-export does (%.9g), where
    std::to_string printed 0.000000."""
    v, f = cube()
    g = libvox.voxelize((v * 1e-7, f), dims=(12, 12, 6), bounds=((-1e-7,) * 3, (1.1e-6, 1.1e-6, 1.1e-6)))
    with pytest.warns(UserWarning) as caught:
        g.save(tmp_path / "py.binvox")
    ours = str(caught[0].message)
    vgrid = tmp_path / "g.vgrid"
    g.save(vgrid)
    proc = subprocess.run([str(tools / "vox-export"), str(vgrid), "-o", str(tmp_path / "cli.binvox")],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    cli = proc.stderr.strip().split(": ", 3)[-1]  # past "vox-export: warning: PATH: "
    assert "0.000000" not in ours and ours.split(": ", 1)[1] == cli, (ours, cli)
