package feelmysign.simplify;

import feelmysign.json.PyRepr;

/**
 * A parameter outside its allowed range, in the reference's words: "{name} = {value} is not
 * allowed; it must be {allowed}" (the value as Python's repr writes it).
 */
public final class ParameterException extends IllegalArgumentException {
  private static final long serialVersionUID = 1L;

  private final String name;
  private final transient Object value;
  private final String allowed;

  public ParameterException(String name, Object value, String allowed) {
    super(name + " = " + PyRepr.of(value) + " is not allowed; it must be " + allowed);
    this.name = name;
    this.value = value;
    this.allowed = allowed;
  }

  /** The parameter's name, as it was given (a paper name such as checkFrame too). */
  public String name() {
    return name;
  }

  public Object value() {
    return value;
  }

  /** What it must be, e.g. "a whole number in [2, 600]". */
  public String allowed() {
    return allowed;
  }
}
