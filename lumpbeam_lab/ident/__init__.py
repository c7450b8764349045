"""Accuracy and coverage of the identification against the models' truth."""
