# Empty compiler generated dependencies file for cairn_tests.
# This may be replaced when dependencies are built.
