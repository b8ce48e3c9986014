"""The C99 controller module (``module``, ``template``, ``source`` and the C texts in ``c/``) and its checks.

``design``, ``optimum`` and ``text`` fill the templates; ``golden``, ``targeted`` and ``vectors`` write the
golden vectors and the host test program; ``verify`` compiles the module and runs it in closed loop against
the simulator. Nothing here imports :mod:`app.exports.drives`.
"""
