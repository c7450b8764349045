"""The shapers by name and the workspace shaping's default, standard library only.

The command line's argument declarations read them without importing numpy
(``lumpbeam_ros.apps.cli.arguments``); :data:`~lumpbeam_ros.core.shaping.shapers.SHAPERS`
implements each name.
"""

#: The shapers: ``zv`` and ``zvd`` (Singer and Seering), ``ei`` (Singhose, 5 % tolerance).
SHAPER_NAMES = ('zv', 'zvd', 'ei')
#: Modes shaped per move by the arm's model unless told otherwise (the slowest ones).
DEFAULT_MAX_MODES = 2
