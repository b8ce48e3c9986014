"""Sub-commands of ``pmsm-commission`` (``main`` holds the parser): simulate, design, bench, serve and the studies."""
