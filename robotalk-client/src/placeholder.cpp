// Placeholder until the client library's sources are listed.
