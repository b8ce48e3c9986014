"""The edges of the tool: command line, web page (viser), plotly figures, files and unit conversion."""
