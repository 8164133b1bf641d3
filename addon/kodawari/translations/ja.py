"""Japanese (日本語): English message -> translation."""

STRINGS = {
}
