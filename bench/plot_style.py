"""The house style of the bench plots (matplotlib, Debian's python3-matplotlib): 800 pixels wide, log axes labelled
in powers of ten, a grey footnote saying where and how the numbers were measured."""
import math

try:
    import matplotlib
except ImportError as e:  # pyenv's or a venv's python3 earlier on PATH has no Debian packages
    raise ImportError("matplotlib not found: apt-get install python3-matplotlib, and run with /usr/bin/python3") from e

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FixedLocator, FuncFormatter, LogFormatterSciNotation, LogLocator, NullFormatter  # noqa: E402

WIDTH_IN, DPI = 8.0, 100  # 800 pixels: the width of a README on a repository page
plt.rcParams.update({"font.size": 10, "axes.titlesize": 11, "axes.labelsize": 10, "legend.fontsize": 8.5,
                     "xtick.labelsize": 9, "ytick.labelsize": 9, "axes.grid": True, "grid.alpha": 0.3,
                     "savefig.dpi": DPI})


def figure(height_in=4.8, ncols=1):
    fig, axes = plt.subplots(1, ncols, figsize=(WIDTH_IN, height_in))
    return fig, axes


def log_axis(ax, which, zero_at=None):
    """A log axis with major ticks at 10^k labelled as such (LogFormatterSciNotation, a LogFormatterMathtext), minor
    ticks labelled 2x10^k, 5x10^k only when the axis spans too few decades to read otherwise. zero_at: a value below
    the data where zeros are drawn, labelled 'none (0)'."""
    set_scale = ax.set_xscale if which == "x" else ax.set_yscale
    axis = ax.xaxis if which == "x" else ax.yaxis
    set_scale("log")
    axis.set_major_locator(LogLocator(base=10, numticks=15))
    axis.set_minor_locator(LogLocator(base=10, subs=range(2, 10), numticks=15))
    def minor(v, pos):  # 2x10^k and 5x10^k, only on an axis of fewer than 2.6 decades
        lo, hi = sorted(axis.get_view_interval())
        k = math.floor(math.log10(v) + 1e-9)
        mantissa = round(v / 10**k)
        if lo <= 0 or math.log10(hi / lo) > 2.6 or mantissa not in (2, 5):
            return ""
        return f"${mantissa}\\times10^{{{k}}}$"
    axis.set_minor_formatter(FuncFormatter(minor))
    mathtext = LogFormatterSciNotation()
    if zero_at is None:
        axis.set_major_formatter(mathtext)
    else:
        axis.set_major_formatter(
            FuncFormatter(lambda v, pos: "none (0)" if abs(v / zero_at - 1) < 1e-6 else mathtext(v, pos)))


def resolution_axis(ax, resolutions):
    """Grid resolution (cells on the longest axis) on a log-2 axis, each measured resolution labelled by its value."""
    ax.set_xscale("log", base=2)
    ax.xaxis.set_major_locator(FixedLocator(resolutions))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, pos: f"{int(round(v))}"))
    ax.xaxis.set_minor_formatter(NullFormatter())


def footnote(fig, text):
    fig.text(0.005, 0.005, text, fontsize=7, color="#555555", ha="left", va="bottom", wrap=True)


def save(fig, path):
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    print(f"wrote {path}")
