"""Robot dynamics: parameters (:mod:`.parameters`), inverse dynamics (:mod:`.rne`)."""
