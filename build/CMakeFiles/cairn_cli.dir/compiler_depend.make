# Empty compiler generated dependencies file for cairn_cli.
# This may be replaced when dependencies are built.
