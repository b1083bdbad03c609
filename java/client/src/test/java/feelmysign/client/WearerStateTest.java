package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertSame;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.time.Instant;
import java.time.ZoneId;
import java.time.ZoneOffset;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;

/** The wearer's choice read from hand-written statuses, as docs/protocol.md writes them. */
class WearerStateTest {
  private static final String PAUSED =
      "{\"online\": true, \"sleeve_id\": \"sleeve1\", \"controls\": {\"paused\": true,"
          + " \"paused_by\": \"button\", \"ceiling\": 0.6,"
          + " \"do_not_disturb_until_ms\": 1795330000000}}";
  private static final long NOW_MS = 1795320000000L;

  @Test
  void theFourFieldsOfTheContractAreRead() {
    assertEquals(new WearerState(true, "button", 0.6, 1795330000000L), WearerState.parse(PAUSED));
  }

  @Test
  void nullsAreUnsetAndAWholeFloatIsATime() {
    WearerState read =
        WearerState.parse(
            "{\"online\": true, \"controls\": {\"paused\": false, \"paused_by\": \"page\","
                + " \"ceiling\": null, \"do_not_disturb_until_ms\": 1795330000000.0}}");
    assertEquals(new WearerState(false, null, null, 1795330000000L), read);
  }

  @ParameterizedTest
  @ValueSource(strings = {"{\"online\": true}", "{\"online\": false}", "{\"controls\": null}"})
  void aStatusWithoutControlsIsNotPaused(String status) {
    assertSame(WearerState.NONE, WearerState.parse(status));
    assertFalse(WearerState.NONE.holds(NOW_MS));
    assertNull(WearerState.NONE.sentence(NOW_MS, ZoneOffset.UTC));
  }

  @ParameterizedTest
  @ValueSource(
      strings = {
        "{\"controls\": {\"paused\": \"yes\"}}",
        "{\"controls\": {}}",
        "{\"controls\": [true]}",
        "{\"controls\": {\"paused\": true, \"paused_by\": 1}}",
        "{\"controls\": {\"paused\": false, \"ceiling\": 1.5}}",
        "{\"controls\": {\"paused\": false, \"ceiling\": -0.1}}",
        "{\"controls\": {\"paused\": false, \"ceiling\": true}}",
        "{\"controls\": {\"paused\": false, \"do_not_disturb_until_ms\": 1.5}}",
        "{\"controls\": {\"paused\": false, \"do_not_disturb_until_ms\": \"14:30\"}}",
        "{\"controls\": {\"paused\": false, \"do_not_disturb_until_ms\": -1}}",
        "[1]",
        "{not json"
      })
  void aFieldOfTheWrongTypeIsNotUnderstood(String status) {
    assertNull(WearerState.parse(status));
  }

  @Test
  void doNotDisturbHoldsUntilItsTimeAndNotAfter() {
    WearerState state = new WearerState(false, null, null, NOW_MS + 60_000);
    assertTrue(state.holds(NOW_MS));
    assertFalse(state.holds(NOW_MS + 60_000));
    String until =
        java.time.format.DateTimeFormatter.ofPattern("HH:mm")
            .format(Instant.ofEpochMilli(NOW_MS + 60_000).atZone(ZoneOffset.UTC));
    assertEquals(
        "the wearer asked not to be disturbed until " + until + ": strokes are refused until then",
        state.sentence(NOW_MS, ZoneOffset.UTC));
  }

  @Test
  void pausedSaysToWaitForTheWearerAndNamesTheCeiling() {
    WearerState state = WearerState.parse(PAUSED);
    assertTrue(state.holds(NOW_MS));
    assertEquals(
        "the wearer paused the sleeve: strokes are refused until the wearer resumes it; wait for"
            + " the wearer (and a ceiling of 60 %)",
        state.sentence(NOW_MS, ZoneId.of("Europe/Berlin")));
  }

  @Test
  void aCeilingCapsWhatTheSleevePlays() {
    WearerState state = new WearerState(false, null, 0.6, null);
    assertFalse(state.holds(NOW_MS));
    assertEquals(0.6, state.playedIntensity(0.8));
    assertEquals(0.5, state.playedIntensity(0.5));
    assertEquals(0.8, WearerState.NONE.playedIntensity(0.8));
    assertEquals(
        "the wearer set a ceiling of 60 %: the sleeve plays no stroke stronger than that",
        state.sentence(NOW_MS, ZoneOffset.UTC));
  }

  @Test
  void onlyAnOnlineStatusTellsTheWearersState() {
    assertEquals(WearerState.parse(PAUSED), SleeveClient.onlineWearer(PAUSED));
    assertNull(SleeveClient.onlineWearer(PAUSED.replace("\"online\": true", "\"online\": false")));
    assertNull(SleeveClient.onlineWearer(""));
  }
}
