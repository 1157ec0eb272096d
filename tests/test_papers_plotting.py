"""Figure files are written atomically and readable (issue 12 items 4 and 7)."""

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from skvalve.papers.plotting import DPI, readable_style, save_figure  # noqa: E402


def _interrupting_savefig(path, **kwargs):
    with open(path, "wb") as handle:
        handle.write(b"\x89PNG partial")  # what an interrupted write leaves behind
    raise KeyboardInterrupt


def test_an_interrupted_write_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "figure.png"
    target.write_bytes(b"old")
    fig = plt.figure(figsize=(6.4, 4.0))
    monkeypatch.setattr(fig, "savefig", _interrupting_savefig)
    with pytest.raises(KeyboardInterrupt):
        save_figure(fig, target)
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["figure.png"]
    plt.close(fig)


def test_a_figure_is_written_at_the_readable_size(tmp_path):
    with readable_style():
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        ax.plot([0, 1], [0, 1], label="line")
        legend = ax.legend()
        assert min(t.get_fontsize() for t in legend.get_texts()) >= 9
        path = save_figure(fig, tmp_path / "ok.png")
    assert matplotlib.image.imread(path).shape[1] == round(6.4 * DPI)
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask  # as any new file, not owner-only
    narrow = plt.figure(figsize=(4.0, 3.0))
    with pytest.raises(ValueError, match="wide"):
        save_figure(narrow, tmp_path / "narrow.png")
    assert not (tmp_path / "narrow.png").exists()
    plt.close("all")
