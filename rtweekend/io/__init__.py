"""What goes in and out around a render: image files (image.py), and the
progress bar and Ctrl-C handling (progress.py)."""
