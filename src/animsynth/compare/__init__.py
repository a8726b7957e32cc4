"""The generators side by side: every motion generator of the project and the classic motion graph, on the
same clips, scored by one set of metrics."""
