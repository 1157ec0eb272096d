"""Network figures are readable (issue 12 item 7): ≥ 150 dpi, ≥ 6 in wide, colour bars, defined symbols."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from skvalve.networks.generate import generate
from skvalve.networks.plotting import (
    MIN_DPI,
    MIN_WIDTH_IN,
    network_figure,
    plot_network,
    plot_orientation_histogram,
    plot_strain_histogram,
)


@pytest.fixture(scope="module")
def network():
    return generate(30.0, 0.0, n_fibers=60, seed=1)


def test_small_low_resolution_figure_is_made_readable_with_a_colour_bar(network):
    fig = plt.figure(figsize=(4.0, 3.0), dpi=72)  # what the thomas2019 chapter used to get
    ax = fig.add_subplot(projection="3d")
    strain = np.linspace(0.0, 0.2, network.n_fibers)
    plot_network(ax, network, strain=strain)
    assert fig.get_dpi() >= MIN_DPI and fig.get_size_inches()[0] >= MIN_WIDTH_IN
    assert fig.get_size_inches()[1] == pytest.approx(3.0 * MIN_WIDTH_IN / 4.0)  # aspect kept
    colour_bars = [a for a in fig.axes if a is not ax]
    assert len(colour_bars) == 1 and "strain" in colour_bars[0].get_ylabel()
    # every coordinate symbol says what it is measured in
    assert "γ" in ax.get_xlabel() and "RVE edge" in ax.get_xlabel()
    plt.close(fig)


def test_uncoloured_network_has_no_colour_bar_and_histograms_define_their_symbols(network):
    fig = network_figure()
    ax3d = fig.add_subplot(131, projection="3d")
    plot_network(ax3d, network)
    assert len(fig.axes) == 1
    ax = fig.add_subplot(132)
    plot_orientation_histogram(ax, network, label="N1")
    legend = ax.legend().get_texts()[0].get_text()
    assert "anisotropy α" in legend and "mean direction μ" in legend
    assert "θ from x" in ax.get_xlabel()
    ax = fig.add_subplot(133)
    plot_strain_histogram(ax, np.array([0.01, 0.05, 0.1]))
    assert "ε = λ − 1" in ax.get_xlabel() and "λ: fiber stretch" in ax.get_xlabel()
    assert fig.get_dpi() >= MIN_DPI and fig.get_size_inches()[0] >= MIN_WIDTH_IN
    plt.close(fig)
