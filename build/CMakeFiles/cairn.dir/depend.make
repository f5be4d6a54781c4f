# Empty dependencies file for cairn.
# This may be replaced when dependencies are built.
