"""Layout of the analysis pictures: the stereonet's title sits on the net (no blank band of paper
between them), and the z axis label of the 3D pictures reads upright from the views they use."""
import matplotlib
import numpy as np
import pytest

from riprap.io import analysis_figures, picture

# The title sits above the "N" label, which stands 3.5 % of the net's size above it: the gap
# between the net and the title must stay a small fraction of the net (it was a third of it).
MAXIMUM_TITLE_GAP_OVER_NET = 0.1


def test_the_stereonet_title_sits_on_the_net(tmp_path, monkeypatch):
    figures = []

    def keep(figure, path, formats=("png", "svg")):
        figures.append(figure)
        return []

    monkeypatch.setattr(analysis_figures, "_save", keep)
    analysis_figures.stereonet_figure(tmp_path / "net.png", np.array([135.0, 20.0, 300.0]),
                                      np.array([30.0, 60.0, 10.0]), title="nose axes\nfabric",
                                      slope_dip_direction_deg=(270.0, 37.0))
    figure = figures[0]
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    net = next(axes for axes in figure.axes if axes.name == "stereonet")
    assert net.get_title() == "nose axes\nfabric"
    assert figure._suptitle is None
    title = net.title.get_window_extent(renderer)
    net_box = net.get_window_extent(renderer)
    assert 0.0 <= title.y0 - net_box.y1 < MAXIMUM_TITLE_GAP_OVER_NET * net_box.height
    matplotlib.pyplot.close(figure)


@pytest.mark.parametrize("view", [(30, -125), (25, -60)])
def test_the_z_label_of_3d_pictures_reads_upright(tmp_path, monkeypatch, view):
    from matplotlib.figure import Figure

    figures = []
    save = Figure.savefig

    def keep(figure, *args, **kwargs):
        save(figure, *args, **kwargs)
        figures.append(figure)

    monkeypatch.setattr(Figure, "savefig", keep)
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    picture.render_bodies_png(tmp_path / "one.png", triangles_world=corners[faces],
                              body_ids=np.zeros(4, dtype=np.int64), view=view, size_px=(500, 400))
    label = figures[0].axes[0].zaxis.label
    # After drawing: mplot3d would have turned a rotating label along the projected axis.
    assert label.get_text() == "z (m)" and label.get_rotation() == 90.0
