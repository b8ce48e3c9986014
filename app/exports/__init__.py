"""Exports: the export menu (``model``), the C99 controller module and its check, the HTML report."""
