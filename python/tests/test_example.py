"""doc/examples/python_mockup.py runs, scores the map and draws its figure."""
import os
import re
import subprocess
import sys

from conftest import SOURCE_DIR


def test_the_example_maps_scores_and_plots_the_mockup(tmp_path):
    out = tmp_path / "layers.png"
    run = subprocess.run([sys.executable, str(SOURCE_DIR / "doc" / "examples" / "python_mockup.py"),
                          str(out)], check=True, capture_output=True, text=True,
                         env=dict(os.environ))
    assert out.stat().st_size > 10000
    rmse_mm = float(re.search(r"all\s+RMSE\s+([\d.]+) mm", run.stdout).group(1))
    within = float(re.search(r"all .*within 3 sigma ([\d.]+)", run.stdout).group(1))
    assert 0 < rmse_mm < 20 and within > 0.9
