"""Sub-commands of ``python -m app`` (``main`` holds the parser): simulate, design, bench, serve and the studies."""
