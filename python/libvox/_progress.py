"""Progress bars for long calls (progress=True): tqdm when it is installed, else none."""


def bar(label):
    """A callable taking the fraction done in [0, 1] that draws a tqdm bar, or None without tqdm."""
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    state = {"bar": tqdm(total=1000, desc=label, unit="", bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}")}

    def update(fraction):
        b = state["bar"]
        if b is None:
            return
        b.n = int(round(1000 * min(max(fraction, 0.0), 1.0)))
        b.refresh()
        if fraction >= 1:
            b.close()
            state["bar"] = None

    return update
