"""Camera side: the checkerboard, the synthetic camera, and the tip tracker."""

__all__ = [
    'bag_frames',
    'board',
    'calibration',
    'camera_info_file',
    'camera_model',
    'config',
    'corners',
    'detect',
    'free_pose',
    'geometry',
    'messages',
    'offline',
    'partial',
    'placement',
    'pose',
    'reprojection',
    'session',
    'synthetic',
    'tracker',
    'sources',
]
