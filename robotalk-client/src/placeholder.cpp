// Placeholder: the client library lands in a follow-up commit.
