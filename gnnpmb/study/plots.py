"""AMOTA against each swept parameter, overall and per class (like the GNN-PMB paper's Table II), as PNGs.

For a key, the points are its values. In a one-at-a-time study they are the rows that vary this key alone plus
the base row at the key's base value; in a full grid each value's point is the best AMOTA over the other keys'
values. Numbers go on a numeric axis (logarithmic when positive values span more than two decades), anything
else on a categorical one.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from gnnpmb.study.evaluate import class_column
from gnnpmb.types import TRACKING_CLASSES

_LOG_SPAN = 100.0


def series(
    key: str,
    keys: Sequence[str],
    rows: Sequence[Mapping[str, Any]],
    column: str,
    base_value: Any,
    one_at_a_time: bool,
) -> list[tuple[Any, float]]:
    """(value of ``key``, ``column``) points sorted by value; rows with no score in ``column`` are left out."""
    points: dict[Any, float] = {}
    for row in rows:
        score = row.get(column)
        if score is None:
            continue
        if one_at_a_time:
            others_set = any(row.get(k) is not None for k in keys if k != key)
            value = row.get(key)
            if others_set or (value is None and base_value is None):
                continue
            value = base_value if value is None else value
            points[value] = score
        else:  # a row of a table that grew by another grid leaves this key at its base value (empty cell)
            value = base_value if row.get(key) is None else row[key]
            if value is None:
                continue
            points[value] = max(score, points.get(value, score))
    try:
        return sorted(points.items())
    except TypeError:
        return sorted(points.items(), key=lambda p: str(p[0]))


def _scale_x(ax: Any, values: Sequence[float]) -> None:
    """A logarithmic x axis when every value is positive and they span more than two decades."""
    if values and min(values) > 0 and max(values) / min(values) > _LOG_SPAN:
        ax.set_xscale("log")


def _numeric(values: Sequence[Any]) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def _pyplot() -> Any:
    """``matplotlib.pyplot`` drawing off screen (Agg), imported only by a study that plots."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: Path) -> None:
    """Write ``fig`` to ``path`` (a PNG, atomically) and close it."""
    from gnnpmb.atomic import atomic_path

    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, dpi=110)
    _pyplot().close(fig)


def _mark_base(ax: Any, base: Any) -> None:
    """A dotted grey line at the key's base value (none without one)."""
    if base is not None:
        ax.axvline(base, color="grey", linestyle=":", linewidth=1)


def plot_file_name(key: str) -> str:
    """``amota_vs_pmb.gate_chi2.png`` (``*`` spelled ``all``)."""
    return f"amota_vs_{key.replace('*', 'all')}.png"


def plot_sweep(
    out_dir: Path,
    keys: Sequence[str],
    rows: Sequence[Mapping[str, Any]],
    base_values: Mapping[str, Any],
    one_at_a_time: bool,
    title: str,
) -> list[Path]:
    """One PNG per swept key in ``out_dir``: overall AMOTA (bold) and each class's AMOTA against the key."""
    plt = _pyplot()
    written = []
    for key in keys:
        fig, ax = plt.subplots(figsize=(7.0, 4.2))
        overall = series(key, keys, rows, "amota", base_values.get(key), one_at_a_time)
        every = [overall] + [
            series(key, keys, rows, class_column(c), base_values.get(key), one_at_a_time) for c in TRACKING_CLASSES
        ]
        values = sorted({v for s in every for v, _ in s}, key=str)
        numeric = _numeric(values)
        position = {v: i for i, v in enumerate(values)}

        def xs(points: list[tuple[Any, float]], numeric: bool = numeric, position: dict = position) -> list:
            return [v if numeric else position[v] for v, _ in points]

        for class_name, points in zip(TRACKING_CLASSES, every[1:], strict=True):
            if points:
                ax.plot(xs(points), [s for _, s in points], marker="o", linewidth=1, alpha=0.7, label=class_name)
        if overall:
            ax.plot(xs(overall), [s for _, s in overall], marker="s", color="black", linewidth=2.5, label="overall")
        if numeric:
            _scale_x(ax, values)
            _mark_base(ax, base_values.get(key))
        else:
            ax.set_xticks(range(len(values)), [str(v) for v in values])
        ax.set_xlabel(key)
        ax.set_ylabel("AMOTA" if one_at_a_time or len(keys) == 1 else "best AMOTA over the other keys")
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="best")
        fig.tight_layout()
        path = Path(out_dir) / plot_file_name(key)
        _save(fig, path)
        written.append(path)
    return written


def plot_ablation(
    path: Path,
    keys: Sequence[str],
    rows: Sequence[Mapping[str, Any]],
    base_values: Mapping[str, Any],
    title: str,
) -> Path:
    """All keys of a one-at-a-time study in one figure (one panel per key, overall AMOTA and per class)."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(keys), figsize=(3.6 * len(keys), 3.6), sharey=True, squeeze=False)
    for ax, key in zip(axes[0], keys, strict=True):
        for class_name in TRACKING_CLASSES:
            points = series(key, keys, rows, class_column(class_name), base_values.get(key), True)
            if points:
                ax.plot(
                    [v for v, _ in points], [s for _, s in points], marker=".", linewidth=1, alpha=0.6, label=class_name
                )
        overall = series(key, keys, rows, "amota", base_values.get(key), True)
        ax.plot(
            [v for v, _ in overall], [s for _, s in overall], marker="s", color="black", linewidth=2.5, label="overall"
        )
        _scale_x(ax, [v for v, _ in overall])
        _mark_base(ax, base_values.get(key))
        ax.set_xlabel(key)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("AMOTA")
    axes[0][-1].legend(fontsize=7, loc="lower right")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _save(fig, path)
    return path
