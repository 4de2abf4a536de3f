"""Reproductions of the documents' experiments against the exact reference."""

#: Journals a study appends its finished parts to (``models``: each part; ``robustness``: each
#: sample), so that an interrupted study keeps them and a rerun into the same folder resumes.
JOURNALS = ("parts.jsonl", "samples.jsonl")
