"""The command line and what it drives: animation, the Dask cluster, image and video files."""
