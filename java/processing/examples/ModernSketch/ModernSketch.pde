// Draw with the mouse; the window simplifier (error-bounded, cut at corners) sends JSON v1
// strokes to a sleeve. Grey: what was sent. Blue: what the sleeve says it played (from its
// events). The sleeve's events are listed on the right; a rejected stroke says why.
// Press S (or space) to Stop: the sleeve stops and drops the rest of the drawing.
// The wearer's choice (paused, "do not disturb", a ceiling) is shown in a band at the top.
import feelmysign.processing.*;
import feelmysign.client.SleeveEvent;
import feelmysign.client.WearerState;

String BROKER = "mqtt://127.0.0.1:1883";
String USER = "sender";
String PASSWORD = "";   // from the broker's credentials.json
String SLEEVE = "sleeve1";

FeelMySign sleeve;
String[] log = new String[12];
int logged = 0;
WearerState wearer = WearerState.NONE;

void setup() {
  size(1280, 720);
  sleeve = new FeelMySign(this)
    .broker(BROKER)
    .login(USER, PASSWORD)
    .sleeve(SLEEVE)
    .window()
    .start();
}

void draw() {
  background(250);
  strokeWeight(10);
  stroke(200);
  sleeve.drawSent();
  strokeWeight(4);
  stroke(30, 90, 220);
  sleeve.drawPlayed();
  strokeWeight(2);
  stroke(0);
  sleeve.drawLine();
  fill(40);
  textSize(14);
  text(sleeve.status() + "   unsent: " + sleeve.unsent(), 12, height - 12);
  for (int i = 0; i < logged; i++) {
    text(log[i], width - 330, 24 + 18 * i);
  }
  // Asked each frame: a "do not disturb" ends by itself at its time.
  String said = wearer.sentence(System.currentTimeMillis(), java.time.ZoneId.systemDefault());
  if (said != null) {
    boolean holds = wearer.holds(System.currentTimeMillis());
    noStroke();
    fill(holds ? color(199, 146, 234) : color(230));
    rect(0, 0, width, 36);
    fill(20);
    textSize(16);
    text(said, 12, 24);
  }
}

// Called by the library inside draw(), on the sketch's thread, when the wearer's choice changes.
void sleeveWearer(WearerState state) {
  wearer = state;
}

// Called by the library inside draw(), on the sketch's thread.
void sleeveEvent(SleeveEvent event) {
  String line = event.type() + (event.seq() == null ? "" : " #" + event.seq());
  if (event.reason() != null) {
    line = line + ": " + event.reason();
  }
  if (logged == log.length) {
    arrayCopy(log, 1, log, 0, log.length - 1);
    logged--;
  }
  log[logged++] = line;
}

void keyPressed() {
  if (key == 's' || key == 'S' || key == ' ') {
    sleeve.stop();
  }
}
