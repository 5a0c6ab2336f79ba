"""Whole jobs, on the top floor: each drives the floors below from a case or a folder to files
written. ``place`` (``riprap place``: underlayer and armour deposition runs, then the pack),
``check`` (``riprap check``: every check a run or placement makes before simulating), ``analyse``
(``riprap analyse``: a pack or a run's frame read, analysed and reported; ``layer_input`` rebuilds
the layer's state from those files)."""
