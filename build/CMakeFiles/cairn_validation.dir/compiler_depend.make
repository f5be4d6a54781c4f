# Empty compiler generated dependencies file for cairn_validation.
# This may be replaced when dependencies are built.
