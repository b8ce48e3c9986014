"""The stock drives' files (ODrive, moteus, VESC, a setpoint CSV) and the stock route that gates them.

``files`` writes them, ``import_drive`` reads a vendor file into a preset, ``stock`` tunes the stock cascade,
``stock_route`` reads a written file back and simulates the drive's own loops from it. Nothing here imports
:mod:`app.exports.firmware`.
"""
