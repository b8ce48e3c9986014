"""Pure ``make_*_figure(result)`` functions that turn results into plotly figure dicts."""
