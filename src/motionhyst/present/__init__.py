"""The paper's figures and the ``reproduce`` report, drawn from the results below (each result
draws itself with its own subpackage's ``figures`` module).
"""

__all__: list[str] = []  # the modules of this package hold its names
